//! Contact manifolds between two shapes at given poses (parry's narrow phase, converted at this
//! one boundary).
//!
//! For shapes a, b at poses `q_a`, `q_b`, every returned point has
//!
//! ```text
//!     n unit (world frame, from a to b),   g = (q_b p_b - q_a p_a) · n <= prediction,
//! ```
//!
//! the witness points `p_a`, `p_b` in the bodies' frames (in a compound's frame, not its
//! part's). `g < 0` is an overlap of depth `-g` (Stewart 2000, §2: the gap function).
//!
//! parry updates a manifold incrementally when the relative motion since the last call is
//! small (it re-projects the old points with absolute thresholds of 1e-3 length and 1 degree).
//! That update is neither exact nor scale invariant, so here every call recomputes the points
//! from the geometry: the cache keeps only parry's manifold buffers (and the last normal, which
//! seeds GJK) and the workspace of composite shapes, so a steady call allocates nothing.

use nalgebra::{Isometry2, Isometry3, Point2, Point3, Vector2, Vector3};
use parry2d_f64::query::{
    ContactManifold as Manifold2, ContactManifoldsWorkspace as Workspace2,
    DefaultQueryDispatcher as Dispatcher2, PersistentQueryDispatcher as _,
};
use parry3d_f64::query::{
    ContactManifold as Manifold3, ContactManifoldsWorkspace as Workspace3,
    DefaultQueryDispatcher as Dispatcher3, PersistentQueryDispatcher as _,
};

use super::shape2::{check_pose2, Shape2};
use super::shape3::{check_pose3, Shape3};
use crate::error::{CoulombError, Result};

/// Which features touch: the parts of a and b (index of a compound's part, of a mesh's or a
/// heightfield's triangle; 0 for a simple shape) and parry's packed feature ids on them
/// (vertex, edge or face, with its index). Equal ids across steps mean the same contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ContactId {
    pub part_a: u32,
    pub part_b: u32,
    pub feature_a: u32,
    pub feature_b: u32,
}

/// One contact point in 3D.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint3 {
    /// unit normal from a to b, world frame.
    pub normal: Vector3<f64>,
    /// signed gap along `normal` (negative: overlap).
    pub gap: f64,
    /// witness point on a, in a's body frame.
    pub point_a: Point3<f64>,
    /// witness point on b, in b's body frame.
    pub point_b: Point3<f64>,
    pub id: ContactId,
}

/// One contact point in 2D.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint2 {
    /// unit normal from a to b, world frame.
    pub normal: Vector2<f64>,
    /// signed gap along `normal` (negative: overlap).
    pub gap: f64,
    /// witness point on a, in a's body frame.
    pub point_a: Point2<f64>,
    /// witness point on b, in b's body frame.
    pub point_b: Point2<f64>,
    pub id: ContactId,
}

/// The buffers of one pair of shapes in 3D, kept from call to call.
#[derive(Default)]
pub struct ContactCache3 {
    manifolds: Vec<Manifold3<(), ()>>,
    workspace: Option<Workspace3>,
}

/// The buffers of one pair of shapes in 2D, kept from call to call.
#[derive(Default)]
pub struct ContactCache2 {
    manifolds: Vec<Manifold2<(), ()>>,
    workspace: Option<Workspace2>,
}

fn check_prediction(prediction: f64) -> Result<()> {
    if !prediction.is_finite() {
        return Err(CoulombError::NonFinite(format!(
            "prediction is {prediction}"
        )));
    }
    if prediction < 0.0 {
        return Err(CoulombError::InvalidParameter(format!(
            "prediction must be >= 0, got {prediction}"
        )));
    }
    Ok(())
}

fn both_static() -> CoulombError {
    CoulombError::InvalidParameter(
        "both shapes are static (mesh, heightfield or half-space): no contact between them"
            .to_string(),
    )
}

fn unsupported(what: String) -> CoulombError {
    CoulombError::InvalidParameter(format!("no contact manifold for {what}"))
}

/// Writes into `out` (cleared first) the contact points of shapes `a` at `pose_a` and `b` at
/// `pose_b` with gap `<= prediction` (`>= 0`). Errors: non-finite poses, a bad prediction, or
/// two static shapes.
pub fn contacts3(
    a: &Shape3,
    pose_a: &Isometry3<f64>,
    b: &Shape3,
    pose_b: &Isometry3<f64>,
    prediction: f64,
    cache: &mut ContactCache3,
    out: &mut Vec<ContactPoint3>,
) -> Result<()> {
    out.clear();
    check_prediction(prediction)?;
    check_pose3("pose a", pose_a)?;
    check_pose3("pose b", pose_b)?;
    if a.is_static() && b.is_static() {
        return Err(both_static());
    }
    for m in &mut cache.manifolds {
        m.points.clear();
    }
    let pos12 = pose_a.inv_mul(pose_b);
    Dispatcher3
        .contact_manifolds(
            &pos12,
            a.parry(),
            b.parry(),
            prediction,
            &mut cache.manifolds,
            &mut cache.workspace,
        )
        .map_err(|_| unsupported(format!("{:?} and {:?}", a.kind(), b.kind())))?;
    for m in &cache.manifolds {
        let part_a = m.subshape_pos1.unwrap_or_else(Isometry3::identity);
        let part_b = m.subshape_pos2.unwrap_or_else(Isometry3::identity);
        let normal = pose_a.rotation * (part_a.rotation * m.local_n1);
        for p in m.points.iter().filter(|p| p.dist <= prediction) {
            out.push(ContactPoint3 {
                normal,
                gap: p.dist,
                point_a: part_a * p.local_p1,
                point_b: part_b * p.local_p2,
                id: ContactId {
                    part_a: m.subshape1,
                    part_b: m.subshape2,
                    feature_a: p.fid1.0,
                    feature_b: p.fid2.0,
                },
            });
        }
    }
    Ok(())
}

/// [`contacts3`] in 2D.
pub fn contacts2(
    a: &Shape2,
    pose_a: &Isometry2<f64>,
    b: &Shape2,
    pose_b: &Isometry2<f64>,
    prediction: f64,
    cache: &mut ContactCache2,
    out: &mut Vec<ContactPoint2>,
) -> Result<()> {
    out.clear();
    check_prediction(prediction)?;
    check_pose2("pose a", pose_a)?;
    check_pose2("pose b", pose_b)?;
    if a.is_static() && b.is_static() {
        return Err(both_static());
    }
    for m in &mut cache.manifolds {
        m.points.clear();
    }
    let pos12 = pose_a.inv_mul(pose_b);
    Dispatcher2
        .contact_manifolds(
            &pos12,
            a.parry(),
            b.parry(),
            prediction,
            &mut cache.manifolds,
            &mut cache.workspace,
        )
        .map_err(|_| unsupported(format!("{:?} and {:?}", a.kind(), b.kind())))?;
    for m in &cache.manifolds {
        let part_a = m.subshape_pos1.unwrap_or_else(Isometry2::identity);
        let part_b = m.subshape_pos2.unwrap_or_else(Isometry2::identity);
        let normal = pose_a.rotation * (part_a.rotation * m.local_n1);
        for p in m.points.iter().filter(|p| p.dist <= prediction) {
            out.push(ContactPoint2 {
                normal,
                gap: p.dist,
                point_a: part_a * p.local_p1,
                point_b: part_b * p.local_p2,
                id: ContactId {
                    part_a: m.subshape1,
                    part_b: m.subshape2,
                    feature_a: p.fid1.0,
                    feature_b: p.fid2.0,
                },
            });
        }
    }
    Ok(())
}
