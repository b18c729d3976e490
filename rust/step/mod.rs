//! The impulse time stepper of Stewart and Trinkle (1996), as surveyed in Stewart (2000).
//!
//! Per step, with M and the contact Jacobians frozen at `q_k`:
//!
//! ```text
//!     v_free  = v_k + h M^{-1} f_k
//!     v_{k+1} = v_free + M^{-1} G P              (G = [J_n^T  J_t^T], P the contact impulses)
//!     q_{k+1} = q_k + h v_{k+1}                  (orientations kept unit)
//! ```
//!
//! The impulses solve the friction-contact problem over the frozen Delassus matrix
//! `W = G^T M^{-1} G` (see [`crate::contact`]) with the free contact velocity
//! `q_c = G^T v_free + (restitution or gap term)`, per contact:
//!
//! - a *closed* contact (`g <= gap_tolerance`) gets Newton's velocity-level restitution
//!   condition `0 <= P_n ⊥ J_n v_{k+1} + e v_n^- >= 0` with `v_n^- = J_n v_k`, or the approach
//!   velocity remembered from the step that closed it (below), whichever is more negative;
//! - an *imminently closing* contact (`g > gap_tolerance`, but the free motion would close it
//!   within the step) gets the gap term `0 <= P_n ⊥ J_n v_{k+1} + g / h >= 0`: the contact may
//!   close during the step but not pass through, and nothing is applied unless it would. When
//!   such a step does push (`P_n > 0`), an impact happened inside it: its approach velocity
//!   `J_n v_k` is recorded for that contact (module `impact`), and the next step applies the
//!   impact law with it whatever the gap left (O(h^2) for a rotating body or a turning
//!   normal): the rebound is then `-e v_n^-`, the record consumed, wherever in the step the
//!   impact fell. With no force acting during the step this is exact; under gravity the
//!   approach is the velocity at the start of the landing step, so with e = 1 each bounce
//!   loses `m g y_k` (y_k the height at that start, at most `m g h |v_n^-|`: first order);
//! - a contact that is far (neither of the above) carries no unknowns (the impact condition
//!   applied to distant bodies would give premature impulses; Stewart 2000).
//!
//! [`Restitution::Poisson`] replaces Newton's condition by an impact phase on `v_k`
//! (compression, then the normal impulse `e P_comp`, Coulomb friction active in both phases:
//! Routh's method for one contact, module `poisson`) followed by an inelastic smooth phase.
//!
//! Energy: for `e <= 1` a step adds no energy beyond the integrator's O(h), except at the
//! plain step's mid-step impact: its rebound uses the approach `v_n^- = J_n v_k` of the
//! landing step's start, while along the step the normal velocity changes at the gap's second
//! derivative `g''` (`-g` under gravity, `|v_t|^2 / d` for two spheres whose normal turns,
//! `n . (ω × (ω × p))` for a turning corner). A bounce then changes the energy by up to
//! `h m_eff |v_n^-| |g''|`: the loss `m g y_k` under gravity, a gain for a turning normal
//! (oblique spheres, `m_eff = 1/2`, `v_n = 2`, `v_t = 1.5` m/s, `d = 0.2` m: 11.25 h J,
//! which the measured gain meets). `locate_impacts` removes both for isolated impacts. And
//! except where Newton's law with friction is known to add it (Stewart 2000; Kane and
//! Levinson's example): a rod at 45 degrees striking at `v = (0.6, -1)` with e = 1 and
//! sticking gains 0.1125 J under Newton's law. Poisson's law with friction in both phases
//! never gains energy for one frictional contact (Glocker, Multibody Syst. Dyn. 2013).
//!
//! The friction law is Coulomb's with the exact disk (NSGS, warm-started by contact identity,
//! with a fallback when it misses its tolerance: see [`StepSettings::fallback`]) or the
//! polyhedral cone (Lemke, warm-started from the previous step's basis of the same contacts:
//! when that basis still solves the step's LCP, no pivot is made), as [`crate::contact`]
//! solves it. Impulses that still solve a step's problem as they are (a resting or sticking
//! body) are kept without a solve; nearly so, NSGS first takes two sweeps towards a thousandth
//! of its tolerance, so the following steps can keep them longer. Frictionless contacts (`mu = 0`) get no tangential impulse
//! (they still carry the tangential row in W: [`crate::contact::ContactProblem`] has one `dim`
//! for all contacts).
//!
//! Bodies ([`BodyKind`]): particles (2D or 3D), planar rigid bodies `(x, y, theta)`, spatial
//! rigid bodies (position, unit quaternion `(w, x, y, z)`; velocity: linear, then the angular
//! velocity in the world frame; inertia given in the body frame). Shapes ([`Shape`]) are sets
//! of body-frame points with a common radius: a point, a disk or sphere (one point), a segment's
//! ends, a box's or polygon's corners. Pairs ([`Pair`]): shape vs a static half-space, and
//! sphere vs sphere (every point of one shape against every point of the other), declared one
//! by one or found each step by the broad phase ([`Pair::Spheres`], a uniform grid over the
//! spheres, O(N) per step: [`broad`]). Solids ([`Solid`]) are the geometry layer's shapes on
//! bodies or static (meshes, heightfields, obstacles): any two of them, or one and a
//! half-space, declared ([`Pair::SolidSolid`], [`Pair::SolidHalfSpace`]) or found each step by
//! a broad phase over their bounding boxes ([`Pair::Solids`]), get their contact points at
//! each state from [`crate::geometry::contacts3`] / [`crate::geometry::contacts2`], named by
//! their features so that warm starts and impact memory follow the same contact point.
//!
//! Islands: a step's contacts that no moving body links (the connected components of W's
//! block pattern) are independent problems; with NSGS on a block-sparse W they are solved
//! apart, each stopping on its own verdict and falling back alone, in parallel
//! ([`with_threads`]), the answer judged on the whole problem and the same on any number of
//! threads.
//!
//! Drift: a velocity-level condition does not enforce `g(q_{k+1}) >= 0` exactly
//! (Stewart 2000). Each contact's normal condition carries the gap's second-order remainder over the step on
//! `v_free`, `min(c, 0) / h` with `c = g(q_k ⊕ h v_free) - g(q_k) - h J_n v_free` (a turning
//! body's contact point curves towards the surface by `(h^2 / 2) n . (ω × (ω × p))`), so a
//! body turning in lasting contact keeps its gap to O(h^3) per step instead of sinking by
//! O(h^2) every step (an O(h) sink over a run). Gaps are monitored in every step's record,
//! and [`Drift`] chooses a correction: none (the default), a velocity bias, or a post-step
//! projection onto `g >= 0`.

pub mod broad;
mod impact;
mod poisson;
mod settings;
mod solid;
mod stepper;

pub use settings::{Drift, Restitution, StepSettings, StepSolver};
pub use solid::{Solid, SolidShape};
pub use stepper::generalized::{
    simulate_generalized, GeneralizedStepper, GeneralizedSystem, GeneralizedTrajectory,
};
pub use stepper::{
    simulate, simulate_joints, simulate_recorded, with_threads, ChunkedRun, ContactColumns,
    ContactRecord, ContactRecords, Joint, JointKind, JointSystemInfo, Records, StepRecord, Stepper,
    Trajectory,
};

use crate::error::{check_finite, CoulombError, Result};

/// What a body is, which fixes its coordinates q and velocities v.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    /// a point mass: q = v = position (dim entries).
    Particle,
    /// a planar rigid body (dim 2 only): q = (x, y, theta), v = (vx, vy, omega).
    Planar,
    /// a spatial rigid body (dim 3 only): q = (x, y, z, qw, qx, qy, qz) with a unit quaternion,
    /// v = (vx, vy, vz, wx, wy, wz), the angular velocity in the world frame.
    Spatial,
}

impl BodyKind {
    /// the number of coordinates.
    pub fn nq(self, dim: usize) -> usize {
        match self {
            BodyKind::Particle => dim,
            BodyKind::Planar => 3,
            BodyKind::Spatial => 7,
        }
    }

    /// the number of velocities.
    pub fn nv(self, dim: usize) -> usize {
        match self {
            BodyKind::Particle => dim,
            BodyKind::Planar => 3,
            BodyKind::Spatial => 6,
        }
    }
}

/// A body with its mass properties, initial state and constant external force.
#[derive(Clone, Debug)]
pub struct Body {
    /// particle, planar or spatial rigid body.
    pub kind: BodyKind,
    /// mass (kg), `> 0`.
    pub mass: f64,
    /// central inertia: planar, `[J]` (kg m^2); spatial, the body-frame 3 x 3 tensor row-major
    /// (symmetric positive definite); particle, empty.
    pub inertia: Vec<f64>,
    /// initial coordinates (`kind.nq(dim)` entries).
    pub q0: Vec<f64>,
    /// initial velocities (`kind.nv(dim)` entries).
    pub v0: Vec<f64>,
    /// a constant force at the centre of mass (N), `dim` entries (besides gravity).
    pub force: Vec<f64>,
}

/// A set of body-frame points with a common radius: the contact features of one body.
#[derive(Clone, Debug)]
pub struct Shape {
    /// the index of the body carrying it.
    pub body: usize,
    /// body-frame points (`dim` entries each): a point, a sphere's centre, a segment's ends,
    /// a box's corners.
    pub points: Vec<Vec<f64>>,
    /// the radius around every point (m), `>= 0` (0 for points and corners).
    pub radius: f64,
}

/// A static half-space `{ x : n . (x - p) <= 0 }`, its boundary a floor, plane or ramp.
#[derive(Clone, Debug)]
pub struct HalfSpace {
    /// a point on the boundary (`dim` entries).
    pub point: Vec<f64>,
    /// the outward normal (`dim` entries, normalised on construction of the stepper).
    pub normal: Vec<f64>,
}

/// Which features may touch, with their friction coefficient and Newton restitution.
#[derive(Clone, Copy, Debug)]
pub enum Pair {
    /// every point of `shape` against `half_space`.
    ShapeHalfSpace {
        /// the shape's index.
        shape: usize,
        /// the half-space's index.
        half_space: usize,
        /// friction coefficient, `>= 0`.
        mu: f64,
        /// Newton restitution coefficient, in `[0, 1]`.
        e: f64,
    },
    /// every point of shape a against every point of shape b (spheres; the shapes must be on
    /// different bodies).
    SphereSphere {
        /// the first shape's index.
        a: usize,
        /// the second shape's index.
        b: usize,
        /// friction coefficient, `>= 0`.
        mu: f64,
        /// Newton restitution coefficient, in `[0, 1]`.
        e: f64,
    },
    /// every pair of spheres on different bodies, found by the stepper itself each step (a
    /// broad phase: a uniform grid, O(N) per step), so they need not be declared one by one.
    /// The spheres are the points of the single-point shapes (a sphere or disk; a point is a
    /// sphere of radius 0). A pair declared by [`Pair::SphereSphere`] keeps its own mu and e.
    /// At most one per scene.
    Spheres {
        /// friction coefficient, `>= 0`.
        mu: f64,
        /// Newton restitution coefficient, in `[0, 1]`.
        e: f64,
    },
    /// solid a against solid b ([`Scene::solids`], not both static nor on one body): their
    /// contact points each step from the geometry layer's narrow phase.
    SolidSolid {
        /// the first solid's index.
        a: usize,
        /// the second solid's index.
        b: usize,
        /// friction coefficient, `>= 0`.
        mu: f64,
        /// Newton restitution coefficient, in `[0, 1]`.
        e: f64,
    },
    /// a solid on a body against a static half-space.
    SolidHalfSpace {
        /// the solid's index.
        solid: usize,
        /// the half-space's index.
        half_space: usize,
        /// friction coefficient, `>= 0`.
        mu: f64,
        /// Newton restitution coefficient, in `[0, 1]`.
        e: f64,
    },
    /// every pair of solids on different bodies (or a body's and a static one), found by the
    /// stepper each step by a broad phase over their bounding boxes (a uniform grid, O(N) per
    /// step). A pair declared by [`Pair::SolidSolid`] keeps its own mu and e. At most one per
    /// scene.
    Solids {
        /// friction coefficient, `>= 0`.
        mu: f64,
        /// Newton restitution coefficient, in `[0, 1]`.
        e: f64,
    },
}

/// A scene: bodies, shapes, half-spaces and contact pairs in a planar (dim 2) or spatial
/// (dim 3) world.
#[derive(Clone, Debug)]
pub struct Scene {
    /// 2 (planar: contacts have a normal and one tangent) or 3 (spatial: two tangents).
    pub dim: usize,
    /// gravitational acceleration (m/s^2), `dim` entries.
    pub gravity: Vec<f64>,
    /// the bodies.
    pub bodies: Vec<Body>,
    /// the shapes.
    pub shapes: Vec<Shape>,
    /// the static half-spaces.
    pub half_spaces: Vec<HalfSpace>,
    /// the pairs that may be in contact.
    pub pairs: Vec<Pair>,
    /// the solids: shapes of the geometry layer on bodies or static (see [`Solid`]).
    pub solids: Vec<Solid>,
}

fn bad(msg: String) -> CoulombError {
    CoulombError::InvalidParameter(msg)
}

fn check_len(name: &str, v: &[f64], n: usize) -> Result<()> {
    if v.len() != n {
        return Err(CoulombError::Shape(format!(
            "{name} has {} entries, expected {n}",
            v.len()
        )));
    }
    check_finite(name, v)
}

impl Scene {
    /// checks every shape, index and value before any work.
    pub fn validate(&self) -> Result<()> {
        let dim = self.dim;
        if dim != 2 && dim != 3 {
            return Err(bad(format!(
                "dim must be 2 (planar) or 3 (spatial), got {dim}"
            )));
        }
        check_len("gravity", &self.gravity, dim)?;
        for (i, b) in self.bodies.iter().enumerate() {
            validate_body(dim, i, b)?;
        }
        for (i, s) in self.shapes.iter().enumerate() {
            if s.body >= self.bodies.len() {
                return Err(bad(format!(
                    "shape {i}: body index {} out of range ({} bodies)",
                    s.body,
                    self.bodies.len()
                )));
            }
            if !(s.radius.is_finite() && s.radius >= 0.0) {
                return Err(bad(format!(
                    "shape {i}: radius must be finite and >= 0, got {}",
                    s.radius
                )));
            }
            if s.points.is_empty() {
                return Err(bad(format!("shape {i} has no points")));
            }
            for p in &s.points {
                check_len(&format!("shape {i} point"), p, dim)?;
            }
        }
        for (i, h) in self.half_spaces.iter().enumerate() {
            check_len(&format!("half-space {i} point"), &h.point, dim)?;
            check_len(&format!("half-space {i} normal"), &h.normal, dim)?;
            let n = h.normal.iter().map(|v| v * v).sum::<f64>().sqrt();
            if n == 0.0 {
                return Err(bad(format!("half-space {i}: the normal is zero")));
            }
        }
        for (i, s) in self.solids.iter().enumerate() {
            s.validate(i, dim, self.bodies.len())?;
        }
        for (i, p) in self.pairs.iter().enumerate() {
            self.validate_pair(i, p)?;
        }
        Ok(())
    }

    /// at most one pair of the kind `is` in the scene.
    fn once(&self, i: usize, is: fn(&Pair) -> bool, what: &str) -> Result<()> {
        let count = self.pairs.iter().filter(|p| is(p)).count();
        if count > 1 {
            return Err(bad(format!(
                "pair {i}: the scene asks {count} times for every {what} pair; at most once"
            )));
        }
        Ok(())
    }

    /// checks the indices of a pair of solids: in range, not both static, not on one body.
    fn validate_solids(&self, i: usize, a: usize, b: usize) -> Result<()> {
        let n = self.solids.len();
        if a >= n || b >= n {
            return Err(bad(format!(
                "pair {i}: solid index out of range ({n} solids)"
            )));
        }
        match (self.solids[a].body, self.solids[b].body) {
            (None, None) => Err(bad(format!(
                "pair {i}: both solids are static: no contact between them"
            ))),
            (Some(x), Some(y)) if x == y => {
                Err(bad(format!("pair {i}: both solids are on body {x}")))
            }
            _ => Ok(()),
        }
    }

    /// checks one contact pair: indices, mu and e.
    fn validate_pair(&self, i: usize, p: &Pair) -> Result<()> {
        let (mu, e) = match *p {
            Pair::ShapeHalfSpace {
                shape,
                half_space,
                mu,
                e,
            } => {
                if shape >= self.shapes.len() || half_space >= self.half_spaces.len() {
                    return Err(bad(format!("pair {i}: index out of range")));
                }
                (mu, e)
            }
            Pair::SphereSphere { a, b, mu, e } => {
                if a >= self.shapes.len() || b >= self.shapes.len() {
                    return Err(bad(format!("pair {i}: index out of range")));
                }
                if self.shapes[a].body == self.shapes[b].body {
                    return Err(bad(format!(
                        "pair {i}: both shapes are on body {}",
                        self.shapes[a].body
                    )));
                }
                (mu, e)
            }
            Pair::Spheres { mu, e } => {
                self.once(i, |p| matches!(p, Pair::Spheres { .. }), "sphere")?;
                (mu, e)
            }
            Pair::SolidSolid { a, b, mu, e } => {
                self.validate_solids(i, a, b)?;
                (mu, e)
            }
            Pair::SolidHalfSpace {
                solid,
                half_space,
                mu,
                e,
            } => {
                if solid >= self.solids.len() || half_space >= self.half_spaces.len() {
                    return Err(bad(format!("pair {i}: index out of range")));
                }
                if self.solids[solid].body.is_none() {
                    return Err(bad(format!(
                        "pair {i}: solid {solid} is static: no contact with a half-space"
                    )));
                }
                (mu, e)
            }
            Pair::Solids { mu, e } => {
                self.once(i, |p| matches!(p, Pair::Solids { .. }), "solid")?;
                (mu, e)
            }
        };
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(bad(format!(
                "pair {i}: mu must be finite and >= 0, got {mu}"
            )));
        }
        if !(0.0..=1.0).contains(&e) {
            return Err(bad(format!("pair {i}: e must be in [0, 1], got {e}")));
        }
        Ok(())
    }

    /// the total number of coordinates.
    pub fn nq(&self) -> usize {
        self.bodies.iter().map(|b| b.kind.nq(self.dim)).sum()
    }

    /// the total number of velocities.
    pub fn nv(&self) -> usize {
        self.bodies.iter().map(|b| b.kind.nv(self.dim)).sum()
    }
}

/// checks one body of a scene of dimension `dim`.
fn validate_body(dim: usize, i: usize, b: &Body) -> Result<()> {
    match (b.kind, dim) {
        (BodyKind::Planar, 3) => {
            return Err(bad(format!("body {i}: a planar rigid body needs dim = 2")))
        }
        (BodyKind::Spatial, 2) => {
            return Err(bad(format!("body {i}: a spatial rigid body needs dim = 3")))
        }
        _ => {}
    }
    if !(b.mass.is_finite() && b.mass > 0.0) {
        return Err(bad(format!(
            "body {i}: mass must be finite and > 0, got {}",
            b.mass
        )));
    }
    check_len(&format!("body {i} q0"), &b.q0, b.kind.nq(dim))?;
    check_len(&format!("body {i} v0"), &b.v0, b.kind.nv(dim))?;
    check_len(&format!("body {i} force"), &b.force, dim)?;
    match b.kind {
        BodyKind::Particle => {}
        BodyKind::Planar => {
            check_len(&format!("body {i} inertia"), &b.inertia, 1)?;
            if b.inertia[0] <= 0.0 {
                return Err(bad(format!(
                    "body {i}: inertia must be > 0, got {}",
                    b.inertia[0]
                )));
            }
        }
        BodyKind::Spatial => {
            check_len(&format!("body {i} inertia"), &b.inertia, 9)?;
            let j = &b.inertia;
            let asym = (j[1] - j[3])
                .abs()
                .max((j[2] - j[6]).abs())
                .max((j[5] - j[7]).abs());
            let scale = j.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            if asym > 1e-12 * scale {
                return Err(bad(format!("body {i}: inertia must be symmetric")));
            }
            // Sylvester's criterion
            let d1 = j[0];
            let d2 = j[0] * j[4] - j[1] * j[3];
            let d3 = det3(j);
            if !(d1 > 0.0 && d2 > 0.0 && d3 > 0.0) {
                return Err(bad(format!("body {i}: inertia must be positive definite")));
            }
            let qn = b.q0[3..7].iter().map(|v| v * v).sum::<f64>().sqrt();
            if (qn - 1.0).abs() > 1e-6 {
                return Err(bad(format!(
                    "body {i}: the orientation quaternion must be unit, has norm {qn}"
                )));
            }
        }
    }
    Ok(())
}

pub(crate) fn det3(j: &[f64]) -> f64 {
    j[0] * (j[4] * j[8] - j[5] * j[7]) - j[1] * (j[3] * j[8] - j[5] * j[6])
        + j[2] * (j[3] * j[7] - j[4] * j[6])
}
