//! The stepper's settings: the time step and step count, the contact solver of every step
//! ([`StepSolver`]), the gap tolerance, warm starts and the solver's fallback, the drift
//! correction ([`Drift`]), the impact law ([`Restitution`]) and the located impacts.

use super::bad;
use crate::contact::{NsgsSettings, PolyhedralSettings};
use crate::error::Result;

/// The contact solver of every step.
#[derive(Clone, Debug)]
pub enum StepSolver {
    /// nonsmooth Gauss-Seidel on the exact friction disk.
    Nsgs(NsgsSettings),
    /// the polyhedral-cone LCP by Lemke's method.
    Lemke(PolyhedralSettings),
}

/// The position-drift correction: gaps are monitored every step, and a projection is checked
/// for its effect on the constraints and the energy (see `drift`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Drift {
    /// none: closed contacts keep whatever penetration the linearised update leaves.
    None,
    /// a velocity bias: a closed contact with `g < 0` gets `0 <= P_n ⊥ J_n v_{k+1} + e v_n^- +
    /// beta g / h >= 0`, pushing a fraction `beta` in (0, 1] of the penetration out per step
    /// (Baumgarte-like; it adds the kinetic energy of that push, and on a toppling stack it
    /// can deepen the worst penetration: see [`Drift::Projection`] for measured figures).
    VelocityBias(f64),
    /// a post-step projection: when some candidate has `g(q_{k+1}) < -gap_tolerance`, the
    /// positions move by the M-smallest displacement `Δq = M^{-1} J_n^T λ`,
    /// `0 <= λ ⊥ J_n M^{-1} J_n^T λ + g >= 0` over every candidate near enough to be reached
    /// (velocities untouched), repeated while the true gaps penetrate. It never deepens the
    /// worst penetration and never raises the energy above the larger of the step's starting
    /// energy and the energy the step left (a lift against gravity is paid from what the step
    /// dissipated; a costlier displacement is shortened or dropped), so it corrects drift
    /// where the motion dissipates and leaves it where nothing is dissipated.
    ///
    /// Measured effects (five balls stacked with 2 mm offsets toppling onto a floor, h = 1e-3,
    /// 1 s): worst penetration 1.6e-4 m and no step gaining energy without correction;
    /// 3.6e-4 m with the bias 0.2, 289 steps gaining up to 1.3e-4 J; 2.0e-5 m with the
    /// projection, no step gaining. Over a class of 12 random stacks (3 to 6 balls, offsets up
    /// to 4 mm, mu 0.1 to 1, 1 s at h = 1e-3 and 1e-4; `examples/drift_stacks.py`), the
    /// projection's worst penetration is 7 to 37 h^2 with no step gaining, against up to
    /// 1.2e-3 m (1e4 h^2 at h = 1e-4) without correction and 130 to 2,700 steps gaining with
    /// the bias; the paths differ, and in 4 of the 24 runs the projected one reaches a
    /// slightly deeper worst gap (at most 1.7x, none beyond 28 h^2) although no step of it
    /// ends deeper than the same step without projection. On the
    /// rod of Painleve's example falling flat (h = 1e-3, 3 s) every gap is >= -1e-12 m with
    /// each option (without correction its sticking end sank 5.3e-9 m before the contact
    /// conditions carried the gap's curvature term).
    Projection,
}

/// The impact law at closed contacts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Restitution {
    /// Newton's: `0 <= P_n ⊥ J_n v_{k+1} + e v_n^- >= 0` (the velocity-level
    /// impact condition of Stewart 2000).
    Newton,
    /// Poisson's: an impact phase on `v_k` alone, compression until the normal velocity
    /// stops (`P_comp`), then the normal restitution impulse `P_rest = e P_comp` (each pair's
    /// `e` as `e_P`), Coulomb friction active in both phases: Routh's integration in impulse
    /// space when one contact impacts alone, the phases solved as wholes for coupled contacts
    /// (see the module `poisson`); the step's smooth phase is then inelastic. For a single
    /// frictionless impact it agrees with Newton's law; for one frictional contact it never
    /// gains energy (Glocker, Multibody Syst. Dyn. 2013).
    Poisson,
}

/// Settings of [`simulate`](super::simulate).
#[derive(Clone, Debug)]
pub struct StepSettings {
    /// the time step h (s), `> 0`.
    pub h: f64,
    /// the number of steps.
    pub steps: usize,
    /// the contact solver and its options.
    pub solver: StepSolver,
    /// a contact with gap at most this (m) is closed; above it, it is open (imminent or far).
    pub gap_tolerance: f64,
    /// start each contact solve from the previous step's impulses of the same contacts.
    pub warm_start: bool,
    /// when NSGS misses its tolerance, try in turn, the first answer that passes taken: above
    /// 32 contacts the robust mode (proximal Newton, NSGS's tolerance) from NSGS's answer
    /// (NSGS then gets 100 sweeps first: a landing layer on a tall pile needs sweeps growing
    /// with its height, the robust mode a few Newton steps); up to 64 contacts the polyhedral
    /// Lemke (tolerance `max(tol, 1e-9)`), and where its answer misses the exact disk the
    /// robust mode from it; above 32 contacts NSGS's remaining sweeps from the best answer so
    /// far. Otherwise the answer with the smallest exact-disk error is kept; the step is
    /// solved if that error is within `max(tol, 1e-9)`. Under [`StepSolver::Lemke`], when every
    /// Lemke path fails: NSGS on the exact disk from Lemke's impulses, with Lemke's
    /// tolerance, its answer kept when it passes the exact rule.
    pub fallback: bool,
    /// the drift correction.
    pub drift: Drift,
    /// the impact law at closed contacts.
    pub restitution: Restitution,
    /// locate isolated impacts within the step: when every active contact is open and one
    /// reaches zero gap first, the step follows the free path to that instant, applies the
    /// impact law there and finishes the step from it (exact rebound timing; with e = 1
    /// under gravity the apex energy is kept bounce after bounce, where the plain step loses
    /// `m g y_k` per bounce). Steps whose impact is not isolated are plain steps.
    pub locate_impacts: bool,
}

impl StepSettings {
    /// NSGS with tolerance 1e-12 and the sticking-set solve (exact impulses on redundant
    /// face contacts; [`NsgsSettings::sticking`]), Lemke fallback, gap tolerance 1e-9 m, warm
    /// start.
    pub fn new(h: f64, steps: usize) -> Self {
        Self {
            h,
            steps,
            solver: StepSolver::Nsgs(NsgsSettings {
                tol: 1e-12,
                sticking: true,
                sticking_at_limit: false,
                ..NsgsSettings::default()
            }),
            gap_tolerance: 1e-9,
            warm_start: true,
            fallback: true,
            drift: Drift::None,
            restitution: Restitution::Newton,
            locate_impacts: false,
        }
    }

    /// checks h and the tolerances before any work.
    pub fn validate(&self) -> Result<()> {
        if !(self.h.is_finite() && self.h > 0.0) {
            return Err(bad(format!(
                "the time step h must be finite and > 0, got {}",
                self.h
            )));
        }
        if !(self.gap_tolerance.is_finite() && self.gap_tolerance >= 0.0) {
            return Err(bad(format!(
                "gap_tolerance must be finite and >= 0, got {}",
                self.gap_tolerance
            )));
        }
        if let Drift::VelocityBias(beta) = self.drift {
            if !(beta > 0.0 && beta <= 1.0) {
                return Err(bad(format!(
                    "the drift velocity bias must lie in (0, 1], got {beta}"
                )));
            }
        }
        Ok(())
    }
}
