//! Solids: the geometry layer's shapes ([`Shape3`], [`Shape2`]) carried by a body or fixed in
//! the world, and their checks.
//!
//! A solid's pose in its body's frame is `(x, y, theta)` in 2D and `(x, y, z, qw, qx, qy,
//! qz)` in 3D (a unit quaternion), so its world pose is the body's pose composed with it,
//! `X = q_body ∘ pose`; a static solid's pose is its world pose. Pairs of solids
//! ([`super::Pair::SolidSolid`], [`super::Pair::SolidHalfSpace`], [`super::Pair::Solids`])
//! get their contact points each step from [`crate::geometry::contacts3`] /
//! [`crate::geometry::contacts2`].

use nalgebra::{Isometry2, Isometry3, Quaternion, Translation3, UnitQuaternion, Vector2};

use crate::error::{check_finite, CoulombError, Result};
use crate::geometry::{Shape2, Shape3};

/// A shape of the geometry layer in a scene of either dimension.
// built once per scene and never moved in a step: the variants' sizes do not matter
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum SolidShape {
    /// a 2D shape (disk, convex polygon, segment, capsule, half-plane), for `dim = 2`.
    Planar(Shape2),
    /// a 3D shape (sphere, box, capsule, cylinder, cone, convex hull, compound, triangle mesh,
    /// heightfield, half-space), for `dim = 3`.
    Spatial(Shape3),
}

impl SolidShape {
    /// whether the shape can only be static (a mesh, a heightfield or a half-space).
    pub fn is_static_only(&self) -> bool {
        match self {
            SolidShape::Planar(s) => s.is_static(),
            SolidShape::Spatial(s) => s.is_static(),
        }
    }

    fn dim(&self) -> usize {
        match self {
            SolidShape::Planar(_) => 2,
            SolidShape::Spatial(_) => 3,
        }
    }
}

/// A shape on a body (or fixed in the world) at a pose.
#[derive(Clone, Debug)]
pub struct Solid {
    /// the body carrying it, or `None` for a static solid (a floor mesh, a heightfield, a
    /// fixed obstacle).
    pub body: Option<usize>,
    /// its pose in the body's frame (in the world for a static solid): `(x, y, theta)` in 2D,
    /// `(x, y, z, qw, qx, qy, qz)` in 3D (the quaternion unit to 1e-6, normalised here).
    pub pose: Vec<f64>,
    /// the shape.
    pub shape: SolidShape,
}

/// A solid's pose as an isometry of the scene's dimension.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Pose {
    Planar(Isometry2<f64>),
    Spatial(Isometry3<f64>),
}

impl Solid {
    /// the pose as an isometry (validated solids only).
    pub(crate) fn isometry(&self) -> Pose {
        let p = &self.pose;
        if p.len() == 3 {
            Pose::Planar(Isometry2::new(Vector2::new(p[0], p[1]), p[2]))
        } else {
            let q = UnitQuaternion::from_quaternion(Quaternion::new(p[3], p[4], p[5], p[6]));
            Pose::Spatial(Isometry3::from_parts(
                Translation3::new(p[0], p[1], p[2]),
                q,
            ))
        }
    }

    /// checks solid `i` of a scene of dimension `dim` with `nbodies` bodies.
    pub(crate) fn validate(&self, i: usize, dim: usize, nbodies: usize) -> Result<()> {
        if self.shape.dim() != dim {
            return Err(CoulombError::InvalidParameter(format!(
                "solid {i}: a {}D shape in a {dim}D scene",
                self.shape.dim()
            )));
        }
        match self.body {
            Some(b) if b >= nbodies => {
                return Err(CoulombError::InvalidParameter(format!(
                    "solid {i}: body index {b} out of range ({nbodies} bodies)"
                )))
            }
            Some(_) if self.shape.is_static_only() => {
                return Err(CoulombError::InvalidParameter(format!(
                    "solid {i}: a triangle mesh, heightfield or half-space is static: it cannot \
                     be carried by a body"
                )))
            }
            _ => {}
        }
        let n = if dim == 2 { 3 } else { 7 };
        if self.pose.len() != n {
            return Err(CoulombError::Shape(format!(
                "solid {i}: pose has {} entries, expected {n}",
                self.pose.len()
            )));
        }
        check_finite(&format!("solid {i} pose"), &self.pose)?;
        if dim == 3 {
            let qn = self.pose[3..].iter().map(|v| v * v).sum::<f64>().sqrt();
            if (qn - 1.0).abs() > 1e-6 {
                return Err(CoulombError::InvalidParameter(format!(
                    "solid {i}: the pose's quaternion must be unit, has norm {qn}"
                )));
            }
        }
        Ok(())
    }
}
