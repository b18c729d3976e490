//! Joints: bilateral constraint rows in the same impulse step as the contacts, eliminated
//! exactly so that every contact solver works on them unchanged.
//!
//! A step with joint rows `J` (`J v = 0` at velocity level, rows in module `rows`) and
//! contacts `G` is Moreau-Jean's step with equality constraints beside the unilateral ones
//! (Acary and Brogliato, "Numerical Methods for Nonsmooth Dynamical Systems", 2008, ch. 10;
//! Stewart 2000, sec. 5 for bilateral constraints in the impulse step):
//!
//! ```text
//!     M (v_{k+1} - v_free) = J^T λ + G P,      J v_{k+1} = b,      contact law on G^T v_{k+1}
//! ```
//!
//! with `b = 0` for the joint rows and a limit's own target (below). With `A = J M^{-1} J^T`
//! the joint impulse is eliminated exactly: `λ = A^+ (b - J v_free - J M^{-1} G P)`, so
//!
//! ```text
//!     v_{k+1} = v_free' + P_J G P,    v_free' = v_free + M^{-1} J^T A^+ (b - J v_free),
//!     P_J = M^{-1} - M^{-1} J^T A^+ J M^{-1},       W = G^T P_J G
//! ```
//!
//! and the contact problem is the one without joints with `M^{-1}` replaced by the
//! constrained inverse mass `P_J` (`v_free` replaced by `v_free'`): NSGS, the robust mode and
//! Lemke solve it unchanged and exactly. `W = G^T M^{-1} G - B^T A^+ B` with `B = J M^{-1} G`:
//! the correction couples the contacts that touch one island of jointed bodies (bodies linked
//! by joints), and enters the assembly as one more block per island; after the solve,
//! `v_{k+1}` is `v_free' + M^{-1} G P` projected again on `J v = b`. A is factored per island
//! by pivoted Cholesky (module `factor`), which drops rows dependent on the others (closed
//! loops; the velocity is unique, the split of the reaction among redundant rows is not).
//! Bodies without joints cost nothing.
//!
//! Limits (a revolute's angle, a prismatic's slide in `[lo, hi]`) are unilateral rows `0 <=
//! λ ⊥ J_l v_{k+1} - b_l >= 0` on the gap `g` to the limit, with Newton's restitution like a
//! frictionless contact: closed (`g <= gap_tolerance`), `b_l = -e min(J_l v_k, 0)`; open, the
//! gap term `b_l = -g / h` (no pass-through within the step), and a step where that pushes
//! records its approach velocity `J_l v_k`, which the next step's rebound target
//! `-e v^-` uses whatever the gap left (impact memory: the rebound is `-e v^-` wherever in
//! the step the stop was struck). Which limits act is found by an active set on the joint
//! problem (the limit rows that would be violated join, any whose impulse would pull leaves;
//! exact for the 1-D problem of one limit) before the contacts are solved; a contact does
//! not release a limit within the step.
//!
//! Drift: the velocity rows keep `C(q)` to O(h^2) per step; after the positions, a
//! mass-weighted Newton projection `q <- q ⊕ (-M^{-1} J^T A^+ C(q))` (Cline and Pai 2003,
//! "Post-stabilization for rigid body simulation with contact and constraints") brings
//! every joint's `C` (and a limit overshoot) back to rounding, without touching velocities.

#[path = "joints/factor.rs"]
mod factor;
#[path = "joints/rows.rs"]
mod rows;
#[path = "joints/step.rs"]
mod step;

use self::rows::{Frame, JointData, WORLD};
use super::{BodyKind, Drift, Restitution, Scene, StepSettings, Stepper};
use crate::error::{check_finite, CoulombError, Result};

pub(super) use self::step::JointSystem;
pub use self::step::JointSystemInfo;

/// What a joint lets body a do relative to body b (or the world).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// a hinge: turns about the axis through the anchor (2D: about the plane's normal).
    Revolute,
    /// a slider: translates along the axis, no turning.
    Prismatic,
    /// a ball joint (3D only): turns about the anchor.
    Spherical,
    /// a weld: no relative motion.
    Fixed,
}

/// A joint between body a and body b (or the world), defined at the scene's initial state.
#[derive(Clone, Debug)]
pub struct Joint {
    /// revolute, prismatic, spherical or fixed.
    pub kind: JointKind,
    /// the first body's index.
    pub a: usize,
    /// the second body's index, or None for the world.
    pub b: Option<usize>,
    /// the joint's anchor, a world point at the initial state (`dim` entries).
    pub anchor: Vec<f64>,
    /// the axis (world, initial state): 3 entries for a revolute or prismatic in 3D, 2 for a
    /// prismatic in 2D, empty otherwise (a 2D revolute turns about the plane's normal).
    pub axis: Vec<f64>,
    /// bounds `(lo, hi)` of the joint coordinate (revolute or prismatic only): the angle
    /// `θ_a - θ_b` in 2D, the turn since the initial state in 3D (within `[-π, π]`), or the
    /// slide of a's anchor from b's along the axis; either bound may be infinite.
    pub limits: Option<(f64, f64)>,
    /// Newton's restitution coefficient at the limits, in `[0, 1]`.
    pub e: f64,
}

fn bad(msg: String) -> CoulombError {
    CoulombError::InvalidParameter(msg)
}

/// checks every joint against a validated scene and the settings, before any work.
pub(super) fn validate(scene: &Scene, joints: &[Joint], settings: &StepSettings) -> Result<()> {
    if joints.is_empty() {
        return Ok(());
    }
    if settings.locate_impacts || settings.restitution == Restitution::Poisson {
        return Err(bad(
            "joints need Newton's restitution without located impacts".to_string(),
        ));
    }
    if settings.drift == Drift::Projection {
        return Err(bad(
            "joints keep their own position projection; use drift 'none' or 'bias'".to_string(),
        ));
    }
    let dim = scene.dim;
    for (i, j) in joints.iter().enumerate() {
        validate_one(scene, i, j)?;
        if dim == 2 && j.kind == JointKind::Spherical {
            return Err(bad(format!("joint {i}: a spherical joint needs dim = 3")));
        }
    }
    Ok(())
}

fn validate_one(scene: &Scene, i: usize, j: &Joint) -> Result<()> {
    let dim = scene.dim;
    let n = scene.bodies.len();
    for body in std::iter::once(j.a).chain(j.b) {
        if body >= n {
            return Err(bad(format!(
                "joint {i}: body index {body} out of range ({n} bodies)"
            )));
        }
        if scene.bodies[body].kind == BodyKind::Particle {
            return Err(bad(format!(
                "joint {i}: body {body} is a particle; joints connect rigid bodies"
            )));
        }
    }
    if j.b == Some(j.a) {
        return Err(bad(format!("joint {i}: joins body {} to itself", j.a)));
    }
    if j.anchor.len() != dim {
        return Err(CoulombError::Shape(format!(
            "joint {i}: the anchor has {} entries, expected {dim}",
            j.anchor.len()
        )));
    }
    check_finite(&format!("joint {i} anchor"), &j.anchor)?;
    let needs_axis = match j.kind {
        JointKind::Prismatic => true,
        JointKind::Revolute => dim == 3,
        _ => false,
    };
    if needs_axis {
        if j.axis.len() != dim {
            return Err(CoulombError::Shape(format!(
                "joint {i}: the axis has {} entries, expected {dim}",
                j.axis.len()
            )));
        }
        check_finite(&format!("joint {i} axis"), &j.axis)?;
        let norm = j.axis.iter().map(|x| x * x).sum::<f64>().sqrt();
        if norm == 0.0 {
            return Err(bad(format!("joint {i}: the axis has zero length")));
        }
    } else if !j.axis.is_empty() {
        return Err(bad(format!(
            "joint {i}: a {:?} joint in {dim}D takes no axis",
            j.kind
        )));
    }
    if !(0.0..=1.0).contains(&j.e) {
        return Err(bad(format!("joint {i}: e must be in [0, 1], got {}", j.e)));
    }
    if let Some((lo, hi)) = j.limits {
        if !matches!(j.kind, JointKind::Revolute | JointKind::Prismatic) {
            return Err(bad(format!(
                "joint {i}: only revolute and prismatic joints take limits"
            )));
        }
        if lo.is_nan() || hi.is_nan() || lo >= hi {
            return Err(bad(format!(
                "joint {i}: limits must satisfy lo < hi, got ({lo}, {hi})"
            )));
        }
        if j.kind == JointKind::Revolute
            && dim == 3
            && (lo < -std::f64::consts::PI || hi > std::f64::consts::PI)
        {
            return Err(bad(format!(
                "joint {i}: a 3D revolute's limits lie in [-pi, pi], got ({lo}, {hi})"
            )));
        }
    }
    Ok(())
}

/// the frame of body `b` (or the world) at coordinates `q`.
fn frame_at(stepper_bodies: &[super::bodies::BodyInfo], dim: usize, q: &[f64], b: usize) -> Frame {
    if b == WORLD {
        Frame::world()
    } else {
        let off = stepper_bodies[b].off_q;
        Frame::of(dim, &q[off..])
    }
}

impl Stepper {
    /// A stepper for `scene` with `joints` (see [`Joint`]): checks the scene, the joints and
    /// the settings before any work. Joints need Newton's restitution, no located impacts
    /// and no contact drift projection (they keep their own).
    pub fn with_joints(scene: &Scene, joints: &[Joint], settings: &StepSettings) -> Result<Self> {
        let mut st = Self::new(scene, settings)?;
        validate(scene, joints, settings)?;
        if joints.is_empty() {
            return Ok(st);
        }
        let dim = scene.dim;
        let mut data = Vec::with_capacity(joints.len());
        for (i, j) in joints.iter().enumerate() {
            let fa = frame_at(&st.bodies, dim, &st.q, j.a);
            let fb = frame_at(&st.bodies, dim, &st.q, j.b.unwrap_or(WORLD));
            let jd = JointData::new(dim, j, &fa, &fb);
            if let (Some((lo, hi)), Some(row)) = (j.limits, jd.coordinate(dim, &fa, &fb)) {
                if row.c < lo || row.c > hi {
                    return Err(bad(format!(
                        "joint {i}: the initial coordinate {} lies outside the limits ({lo}, {hi})",
                        row.c
                    )));
                }
            }
            data.push(jd);
        }
        st.joints = Some(Box::new(JointSystem::new(dim, st.bodies.len(), data)));
        Ok(st)
    }

    /// turns the joints' position projection (on by default) off or on.
    pub fn set_joint_projection(&mut self, on: bool) {
        if let Some(js) = self.joints.as_mut() {
            js.projection = on;
        }
    }

    /// the largest violation `|C(q)|` of every joint's equality rows at the current state
    /// (m for anchors and slides, rad for orientations), and of the limits (how far past).
    pub fn joint_violation(&self) -> f64 {
        self.joints
            .as_ref()
            .map_or(0.0, |js| js.violation(&self.bodies, &self.q))
    }

    /// the joint islands' sizes and ranks at the last step (see [`JointSystemInfo`]).
    pub fn joint_info(&self) -> Vec<JointSystemInfo> {
        self.joints.as_ref().map_or(Vec::new(), |js| js.info())
    }
}
