//! The interface of a mechanism in generalized coordinates that the impulse time stepper
//! calls back at each state: `M(q)`, `f(q, v, t)`, the contacts' gaps and Jacobian rows, and
//! the potential energy (Moreau's measure differential inclusion
//! `M(q) dv = f(q, v, t) dt + J_n^T dP_n + J_t^T dP_t`, `dq = v dt`; Stewart 2000).

use crate::error::Result;

/// A mechanism in generalized coordinates (`dq/dt = v`, so `nq = nv`) whose mass matrix,
/// forces and contacts the stepper asks for at each state it reaches.
pub trait GeneralizedSystem {
    /// 2 (a contact has a normal and one tangent) or 3 (two tangents).
    fn dim(&self) -> usize;
    /// the number of generalized coordinates and velocities.
    fn nv(&self) -> usize;
    /// per contact, its friction coefficient `mu >= 0` and restitution `e` in `[0, 1]`.
    fn laws(&self) -> Vec<(f64, f64)>;
    /// `M(q)`, row-major `nv x nv`, symmetric positive definite, into `m`.
    fn mass(&mut self, q: &[f64], m: &mut [f64]) -> Result<()>;
    /// the generalized forces `f(q, v, t)` into `f` (`nv` entries).
    fn force(&mut self, q: &[f64], v: &[f64], t: f64, f: &mut [f64]) -> Result<()>;
    /// per contact i its gap `gaps[i]` (> 0 when separated) and the rows of its Jacobian,
    /// normal first then the tangents, at `rows[(i dim + α) nv ..][..nv]`. Called at each
    /// state, and once more in a step with active contacts at the predicted state
    /// `q_k + h v_free` (whose gaps give the gap's second-order term over the step).
    fn contacts(&mut self, q: &[f64], gaps: &mut [f64], rows: &mut [f64]) -> Result<()>;
    /// the potential energy `V(q)` of the forces, for the records (0 when not known).
    fn potential(&mut self, q: &[f64]) -> Result<f64>;
}

impl<T: GeneralizedSystem + ?Sized> GeneralizedSystem for &mut T {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn nv(&self) -> usize {
        (**self).nv()
    }
    fn laws(&self) -> Vec<(f64, f64)> {
        (**self).laws()
    }
    fn mass(&mut self, q: &[f64], m: &mut [f64]) -> Result<()> {
        (**self).mass(q, m)
    }
    fn force(&mut self, q: &[f64], v: &[f64], t: f64, f: &mut [f64]) -> Result<()> {
        (**self).force(q, v, t, f)
    }
    fn contacts(&mut self, q: &[f64], gaps: &mut [f64], rows: &mut [f64]) -> Result<()> {
        (**self).contacts(q, gaps, rows)
    }
    fn potential(&mut self, q: &[f64]) -> Result<f64> {
        (**self).potential(q)
    }
}
