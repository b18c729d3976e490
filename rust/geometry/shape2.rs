//! Shapes in 2D, each built by a validating constructor.
//!
//! Body frames: a disk is centred at the origin; a capsule is the set of points within
//! `radius` of its segment; a half-space is `{x : n · x <= 0}` with its outward unit normal; a
//! compound's parts are at their poses in its frame; a polyline (static) is its vertices in the
//! world frame.

use nalgebra::{Isometry2, Point2, Unit, Vector2};
use parry2d_f64::shape::{
    Ball, Capsule, Compound, ConvexPolygon, HalfSpace, Polyline, Segment, Shape as ParryShape,
    SharedShape,
};

use super::validate::{extent, finite_points, positive, spans_2d};
use crate::error::{CoulombError, Result};

/// Which shape a [`Shape2`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShapeKind2 {
    Disk,
    ConvexPolygon,
    Segment,
    Capsule,
    Compound,
    Polyline,
    HalfSpace,
}

#[derive(Clone)]
enum Repr2 {
    Disk(Ball),
    ConvexPolygon(ConvexPolygon),
    Segment(Segment),
    Capsule(Capsule),
    Compound(Compound),
    Polyline(Polyline),
    HalfSpace(HalfSpace),
}

/// A validated 2D shape in its body frame.
#[derive(Clone)]
pub struct Shape2 {
    repr: Repr2,
    /// a number unique to the shape (kept by clones), naming it in contact caches.
    id: u64,
}

impl std::fmt::Debug for Shape2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Shape2::{:?}", self.kind())
    }
}

pub(crate) fn check_pose2(name: &str, pose: &Isometry2<f64>) -> Result<()> {
    let t = pose.translation.vector;
    let c = pose.rotation.complex();
    if t.iter().all(|x| x.is_finite()) && c.re.is_finite() && c.im.is_finite() {
        Ok(())
    } else {
        Err(CoulombError::NonFinite(format!("{name}: pose {pose:?}")))
    }
}

impl Shape2 {
    /// A disk of `radius > 0`.
    pub fn disk(radius: f64) -> Result<Self> {
        Ok(Self::new(Repr2::Disk(Ball::new(positive(
            "disk radius",
            radius,
        )?))))
    }

    /// The box `[-hx, hx] x [-hy, hy]` as a convex polygon.
    pub fn rectangle(half_extents: [f64; 2]) -> Result<Self> {
        let hx = positive("rectangle half extent x", half_extents[0])?;
        let hy = positive("rectangle half extent y", half_extents[1])?;
        Self::convex_polygon(&[[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    }

    /// The convex hull of `points`: finite, not all on one line (relative to their extent).
    pub fn convex_polygon(points: &[[f64; 2]]) -> Result<Self> {
        finite_points("convex polygon", points)?;
        if !spans_2d(points) {
            return Err(CoulombError::InvalidParameter(format!(
                "convex polygon of {} points is degenerate: they lie on a line or a point",
                points.len()
            )));
        }
        // built at the unit 2^k nearest the largest coordinate and scaled back (exact):
        // parry's edge normals need edges longer than an absolute epsilon
        let size = points.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
        let unit = 2f64.powi(size.log2().round().clamp(-1000.0, 1000.0) as i32);
        let pts: Vec<Point2<f64>> = points.iter().map(|&p| Point2::from(p) / unit).collect();
        super::hull::convex_polygon(&pts)
            .and_then(|p| p.scaled(&Vector2::repeat(unit)))
            .map(|p| Self::new(Repr2::ConvexPolygon(p)))
            .ok_or_else(|| {
                CoulombError::InvalidParameter("convex polygon could not be built".to_string())
            })
    }

    /// The segment `[a, b]`, `a != b` (relative to their size).
    pub fn segment(a: [f64; 2], b: [f64; 2]) -> Result<Self> {
        finite_points("segment", &[a, b])?;
        let len = extent(&[a, b]);
        let size = a.iter().chain(&b).fold(0.0f64, |m, x| m.max(x.abs()));
        if len <= 1e-12 * size || len == 0.0 {
            return Err(CoulombError::InvalidParameter(format!(
                "segment from {a:?} to {b:?} has zero length"
            )));
        }
        Ok(Self::new(Repr2::Segment(Segment::new(a.into(), b.into()))))
    }

    /// The points within `radius > 0` of the segment `[a, b]`.
    pub fn capsule(a: [f64; 2], b: [f64; 2], radius: f64) -> Result<Self> {
        finite_points("capsule segment", &[a, b])?;
        let r = positive("capsule radius", radius)?;
        Ok(Self::new(Repr2::Capsule(Capsule::new(
            a.into(),
            b.into(),
            r,
        ))))
    }

    /// The union of convex `parts` (disks, convex polygons, segments, capsules; at least
    /// one), each at its pose in the compound's frame.
    pub fn compound(parts: &[(Isometry2<f64>, Shape2)]) -> Result<Self> {
        if parts.is_empty() {
            return Err(CoulombError::Shape(
                "a compound needs at least one part".into(),
            ));
        }
        let mut shared = Vec::with_capacity(parts.len());
        for (k, (pose, part)) in parts.iter().enumerate() {
            check_pose2(&format!("compound part {k}"), pose)?;
            if part.is_static() || part.kind() == ShapeKind2::Compound {
                return Err(CoulombError::InvalidParameter(format!(
                    "compound part {k} is a {:?}: parts must be convex",
                    part.kind()
                )));
            }
            shared.push((*pose, SharedShape(part.parry().clone_dyn().into())));
        }
        Ok(Self::new(Repr2::Compound(Compound::new(shared))))
    }

    /// A static polyline through `vertices` (finite, at least two, no segment shorter than
    /// `1e-9` of the polyline's extent). Bodies touch it from either side; a contact on a
    /// segment's interior takes the segment's normal (the left of the direction of travel,
    /// or its opposite: the side the body is on).
    pub fn polyline(vertices: &[[f64; 2]]) -> Result<Self> {
        finite_points("polyline vertices", vertices)?;
        if vertices.len() < 2 {
            return Err(CoulombError::Shape(format!(
                "a polyline needs at least two vertices, got {}",
                vertices.len()
            )));
        }
        let scale = extent(vertices);
        for (k, w) in vertices.windows(2).enumerate() {
            let len = extent(w);
            if len <= super::validate::FLAT * scale || len == 0.0 {
                return Err(CoulombError::InvalidParameter(format!(
                    "polyline segment {k} from {:?} to {:?} has zero length",
                    w[0], w[1]
                )));
            }
        }
        let pts: Vec<Point2<f64>> = vertices.iter().map(|&p| p.into()).collect();
        Ok(Self::new(Repr2::Polyline(Polyline::new(pts, None))))
    }

    /// The half-plane `{x : n · x <= 0}` of outward `normal` (finite, nonzero; normalised).
    pub fn half_space(normal: [f64; 2]) -> Result<Self> {
        finite_points("half-space normal", &[normal])?;
        let n = Unit::try_new(Vector2::from(normal), f64::MIN_POSITIVE).ok_or_else(|| {
            CoulombError::InvalidParameter("half-space normal is zero".to_string())
        })?;
        Ok(Self::new(Repr2::HalfSpace(HalfSpace::new(n))))
    }

    fn new(repr: Repr2) -> Self {
        Self {
            repr,
            id: super::validate::next_shape_id(),
        }
    }

    pub(crate) fn id(&self) -> u64 {
        self.id
    }

    /// The parry shape scaled by `k > 0` (exactly, for `k` a power of two).
    pub(crate) fn scaled_parry(&self, k: f64) -> Option<Box<dyn ParryShape>> {
        self.parry().scale_dyn(&Vector2::repeat(k), 0)
    }

    /// The radius a disk or a capsule rounds its core by, 0 for other shapes (see
    /// `Shape3::rounding`).
    pub(crate) fn rounding(&self) -> f64 {
        match &self.repr {
            Repr2::Disk(s) => s.radius,
            Repr2::Capsule(c) => c.radius,
            _ => 0.0,
        }
    }

    /// Which shape this is.
    pub fn kind(&self) -> ShapeKind2 {
        match &self.repr {
            Repr2::Disk(_) => ShapeKind2::Disk,
            Repr2::ConvexPolygon(_) => ShapeKind2::ConvexPolygon,
            Repr2::Segment(_) => ShapeKind2::Segment,
            Repr2::Capsule(_) => ShapeKind2::Capsule,
            Repr2::Compound(_) => ShapeKind2::Compound,
            Repr2::Polyline(_) => ShapeKind2::Polyline,
            Repr2::HalfSpace(_) => ShapeKind2::HalfSpace,
        }
    }

    /// Whether the shape is static only (a polyline, a half-space): two static shapes never
    /// touch.
    pub fn is_static(&self) -> bool {
        matches!(self.kind(), ShapeKind2::Polyline | ShapeKind2::HalfSpace)
    }

    /// Whether the shape is a half-space (whose contacts parry computes in closed form).
    pub(crate) fn is_half_space(&self) -> bool {
        self.kind() == ShapeKind2::HalfSpace
    }

    /// The parry shape (the narrow phase's boundary).
    pub(crate) fn parry(&self) -> &dyn ParryShape {
        match &self.repr {
            Repr2::Disk(s) => s,
            Repr2::ConvexPolygon(s) => s,
            Repr2::Segment(s) => s,
            Repr2::Capsule(s) => s,
            Repr2::Compound(s) => s,
            Repr2::Polyline(s) => s,
            Repr2::HalfSpace(s) => s,
        }
    }

    /// The half diagonal of the shape's bounding box in its frame; `None` for a half-space.
    pub(crate) fn size(&self) -> Option<f64> {
        let b = self.parry().compute_local_aabb();
        let d = 0.5 * (b.maxs - b.mins).norm();
        (d.is_finite() && d > 0.0).then_some(d)
    }

    /// The axis-aligned bounding box `(min, max)` at `pose` (infinite for a half-space).
    pub fn aabb(&self, pose: &Isometry2<f64>) -> ([f64; 2], [f64; 2]) {
        let b = self.parry().compute_aabb(pose);
        (b.mins.coords.into(), b.maxs.coords.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_2d_shapes_are_refused_with_errors() {
        assert!(Shape2::disk(-1.0).is_err());
        assert!(Shape2::rectangle([1.0, 0.0]).is_err());
        assert!(Shape2::convex_polygon(&[[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]).is_err());
        assert!(Shape2::convex_polygon(&[[0.0, 0.0], [1.0, 0.0]]).is_err());
        assert!(Shape2::convex_polygon(&[[0.0, 0.0], [1.0, f64::NAN], [0.0, 1.0]]).is_err());
        assert!(Shape2::segment([1.0, 1.0], [1.0, 1.0]).is_err());
        assert!(Shape2::capsule([0.0, 0.0], [1.0, 0.0], 0.0).is_err());
        assert!(Shape2::half_space([0.0, 0.0]).is_err());
        assert!(Shape2::half_space([f64::NAN, 1.0]).is_err());
        assert!(Shape2::compound(&[]).is_err());
        let floor = Shape2::half_space([0.0, 1.0]);
        if let Ok(floor) = floor {
            assert!(Shape2::compound(&[(Isometry2::identity(), floor)]).is_err());
        }
        assert!(Shape2::polyline(&[[0.0, 0.0]]).is_err());
        assert!(Shape2::polyline(&[[0.0, 0.0], [1.0, 0.0], [1.0, 0.0]]).is_err());
        assert!(Shape2::polyline(&[[0.0, 0.0], [f64::INFINITY, 0.0]]).is_err());
    }
}
