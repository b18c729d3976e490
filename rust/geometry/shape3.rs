//! Shapes in 3D, each built by a validating constructor.
//!
//! Body frames: a sphere, box, cylinder and cone are centred at the body frame's origin; the
//! cylinder's and cone's axis is the frame's y axis (the cone's apex at `y = +h`, its base disc
//! at `y = -h`); a capsule is the set of points within `radius` of its segment; a half-space is
//! `{x : n · x <= 0}` with its outward unit normal `n`; a heightfield spans the frame's x-z
//! plane with heights along y.

use nalgebra::{DMatrix, Isometry3, Point3, Unit, Vector3};
use parry3d_f64::shape::{
    Ball, Capsule, Compound, Cone, ConvexPolyhedron, Cylinder, HalfSpace, HeightField,
    HeightFieldFlags, Shape as ParryShape, SharedShape, TriMesh, TriMeshFlags,
};

use super::validate::{extent, finite_points, positive, spans_3d, triangle_area2, FLAT};
use crate::error::{CoulombError, Result};

/// Which shape a [`Shape3`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShapeKind3 {
    Sphere,
    Cuboid,
    Capsule,
    Cylinder,
    Cone,
    ConvexHull,
    Compound,
    TriangleMesh,
    Heightfield,
    HalfSpace,
}

/// The shape's data (parry's shapes, built only from validated input).
#[derive(Clone)]
enum Repr3 {
    Sphere(Ball),
    /// the polyhedron and its half extents (its corners are at exactly `+-half`).
    Cuboid(ConvexPolyhedron, [f64; 3]),
    Capsule(Capsule),
    Cylinder(Cylinder),
    Cone(Cone),
    ConvexHull(ConvexPolyhedron),
    Compound(Compound),
    TriangleMesh(TriMesh),
    Heightfield(HeightField),
    HalfSpace(HalfSpace),
}

/// A validated 3D shape in its body frame.
#[derive(Clone)]
pub struct Shape3 {
    repr: Repr3,
    /// a number unique to the shape (kept by clones), naming it in contact caches.
    id: u64,
}

impl std::fmt::Debug for Shape3 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Shape3::{:?}", self.kind())
    }
}

/// The convex hull of `points` (module `hull`), built at the unit `2^k` nearest their largest
/// coordinate and scaled back (exactly, a power of two): parry's polyhedron drops edges
/// shorter than an absolute epsilon.
fn hull(points: &[Point3<f64>]) -> Option<ConvexPolyhedron> {
    let size = points.iter().map(|p| p.coords.amax()).fold(0.0, f64::max);
    let unit = 2f64.powi(size.log2().round().clamp(-1000.0, 1000.0) as i32);
    let at_unit: Vec<Point3<f64>> = points.iter().map(|p| p / unit).collect();
    super::hull::convex_hull(&at_unit)?.scaled(&Vector3::repeat(unit))
}

/// The box `[-half, half]` as a polyhedron, from its 12 triangles (two per face, turned
/// outwards), built at the unit `2^k` nearest its largest extent and scaled back (exact): a
/// convex hull of its corners has tolerances relative to the largest extent, which made a
/// 2 x 2e-4 x 2 plate a single face.
fn box_polyhedron(half: [f64; 3]) -> Option<ConvexPolyhedron> {
    let size = half.iter().fold(0.0f64, |m, &x| m.max(x));
    let unit = 2f64.powi(size.log2().round().clamp(-1000.0, 1000.0) as i32);
    // corner k has the sign of bit i of k along axis i
    let corner = |k: u32| {
        let s = |i: usize| if k & (1 << i) == 0 { -1.0 } else { 1.0 };
        Point3::new(
            s(0) * half[0] / unit,
            s(1) * half[1] / unit,
            s(2) * half[2] / unit,
        )
    };
    let points: Vec<Point3<f64>> = (0..8).map(corner).collect();
    let mut triangles = Vec::with_capacity(12);
    for axis in 0..3 {
        let (j, l) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0u32, 1] {
            // the face's corners in order around it
            let at = |bj: u32, bl: u32| (side << axis) | (bj << j) | (bl << l);
            let quad = [at(0, 0), at(1, 0), at(1, 1), at(0, 1)];
            for t in [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]] {
                let [a, b, c] = t.map(|k| points[k as usize]);
                // outwards: the normal points away from the centre (the origin)
                let outward = (b - a).cross(&(c - a)).dot(&a.coords) > 0.0;
                triangles.push(if outward { t } else { [t[0], t[2], t[1]] });
            }
        }
    }
    ConvexPolyhedron::from_convex_mesh(points, &triangles)?.scaled(&Vector3::repeat(unit))
}

fn check_pose(name: &str, pose: &Isometry3<f64>) -> Result<()> {
    let t = pose.translation.vector;
    let q = pose.rotation.coords;
    if t.iter().chain(q.iter()).all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(CoulombError::NonFinite(format!("{name}: pose {pose:?}")))
    }
}

pub(crate) fn check_pose3(name: &str, pose: &Isometry3<f64>) -> Result<()> {
    check_pose(name, pose)
}

impl Shape3 {
    /// A ball of `radius > 0`.
    pub fn sphere(radius: f64) -> Result<Self> {
        Ok(Self::new(Repr3::Sphere(Ball::new(positive(
            "sphere radius",
            radius,
        )?))))
    }

    /// A box with half side lengths `half_extents`, each > 0.
    ///
    /// Held as the convex polyhedron of its 8 corners. Two boxes' manifold comes from their
    /// separating axes where a face axis decides it exactly (module `box_pair`); otherwise
    /// (an edge axis, or corners within the prediction of each other, where the largest axis
    /// separation is only a lower bound of the distance) the polyhedra go through GJK, which
    /// gives the distance.
    pub fn cuboid(half_extents: [f64; 3]) -> Result<Self> {
        let [x, y, z] = half_extents;
        let (x, y, z) = (
            positive("box half extent x", x)?,
            positive("box half extent y", y)?,
            positive("box half extent z", z)?,
        );
        let half = [x, y, z];
        // a box far thinner than it is long loses corners to the hull's tolerance: refused
        // rather than kept as another polyhedron (its half extents are read as its corners)
        let exact = |h: &ConvexPolyhedron| {
            let b = h.local_aabb();
            h.points().len() == 8
                && b.maxs.coords == Vector3::from(half)
                && b.mins.coords == -Vector3::from(half)
        };
        match box_polyhedron(half) {
            Some(h) if exact(&h) => Ok(Self::new(Repr3::Cuboid(h, half))),
            _ => Err(CoulombError::InvalidParameter(format!(
                "box half extents {half:?} span too many orders of magnitude for a polyhedron \
                 (it loses corners); use extents within a factor 1e12 of each other"
            ))),
        }
    }

    /// The points within `radius > 0` of the segment `[a, b]` (`a == b` gives a sphere).
    pub fn capsule(a: [f64; 3], b: [f64; 3], radius: f64) -> Result<Self> {
        finite_points("capsule segment", &[a, b])?;
        let r = positive("capsule radius", radius)?;
        Ok(Self::new(Repr3::Capsule(Capsule::new(
            a.into(),
            b.into(),
            r,
        ))))
    }

    /// A cylinder along y of half height `half_height > 0` and `radius > 0`.
    pub fn cylinder(half_height: f64, radius: f64) -> Result<Self> {
        let h = positive("cylinder half height", half_height)?;
        let r = positive("cylinder radius", radius)?;
        Ok(Self::new(Repr3::Cylinder(Cylinder::new(h, r))))
    }

    /// A cone along y (apex at `+half_height`) with base `radius > 0`.
    pub fn cone(half_height: f64, radius: f64) -> Result<Self> {
        let h = positive("cone half height", half_height)?;
        let r = positive("cone radius", radius)?;
        Ok(Self::new(Repr3::Cone(Cone::new(h, r))))
    }

    /// The convex hull of `points`: finite, and not all on one plane (relative to their
    /// extent, see [`FLAT`]).
    pub fn convex_hull(points: &[[f64; 3]]) -> Result<Self> {
        finite_points("convex hull", points)?;
        if !spans_3d(points) {
            return Err(CoulombError::InvalidParameter(format!(
                "convex hull of {} points is degenerate: they lie on a plane, a line or a point",
                points.len()
            )));
        }
        let pts: Vec<Point3<f64>> = points.iter().map(|&p| p.into()).collect();
        hull(&pts)
            .map(|h| Self::new(Repr3::ConvexHull(h)))
            .ok_or_else(|| {
                CoulombError::InvalidParameter("convex hull could not be built".to_string())
            })
    }

    /// The union of convex `parts`, each at its pose in the compound's frame (spheres, boxes,
    /// capsules, cylinders, cones and hulls; at least one).
    pub fn compound(parts: &[(Isometry3<f64>, Shape3)]) -> Result<Self> {
        if parts.is_empty() {
            return Err(CoulombError::Shape(
                "a compound needs at least one part".into(),
            ));
        }
        let mut shared = Vec::with_capacity(parts.len());
        for (k, (pose, part)) in parts.iter().enumerate() {
            check_pose(&format!("compound part {k}"), pose)?;
            if !part.is_convex() {
                return Err(CoulombError::InvalidParameter(format!(
                    "compound part {k} is a {:?}: parts must be convex",
                    part.kind()
                )));
            }
            shared.push((*pose, part.shared()));
        }
        Ok(Self::new(Repr3::Compound(Compound::new(shared))))
    }

    /// A static triangle mesh: `vertices` finite, `triangles` indexing them, wound counter-
    /// clockwise seen from outside (the side contacts come from) and consistently, no triangle
    /// of area below `FLAT L^2` (`L` the mesh's extent), and no edge shared by more than two
    /// triangles (manifold).
    pub fn triangle_mesh(vertices: &[[f64; 3]], triangles: &[[u32; 3]]) -> Result<Self> {
        finite_points("triangle mesh vertices", vertices)?;
        if triangles.is_empty() {
            return Err(CoulombError::Shape(
                "a triangle mesh needs a triangle".into(),
            ));
        }
        let scale = extent(vertices);
        let n = vertices.len();
        let mut edges = Vec::with_capacity(3 * triangles.len());
        for (k, t) in triangles.iter().enumerate() {
            if t.iter().any(|&i| i as usize >= n) {
                return Err(CoulombError::Shape(format!(
                    "triangle {k} {t:?} indexes past the {n} vertices"
                )));
            }
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            if triangle_area2(a, b, c) <= 2.0 * FLAT * scale * scale {
                return Err(CoulombError::InvalidParameter(format!(
                    "triangle {k} {t:?} is degenerate (zero area)"
                )));
            }
            for (i, j) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
                edges.push((i.min(j), i.max(j)));
            }
        }
        edges.sort_unstable();
        for w in edges.windows(3) {
            if w[0] == w[2] {
                return Err(CoulombError::InvalidParameter(format!(
                    "edge {:?} is shared by more than two triangles (non-manifold mesh)",
                    w[0]
                )));
            }
        }
        let verts: Vec<Point3<f64>> = vertices.iter().map(|&p| p.into()).collect();
        let mut mesh = TriMesh::new(verts, triangles.to_vec())
            .map_err(|e| CoulombError::InvalidParameter(format!("triangle mesh: {e}")))?;
        // oriented, with its internal edges fixed: a contact on an edge or vertex between
        // triangles gets a normal within the cone of the adjacent faces' normals
        let flags = TriMeshFlags::HALF_EDGE_TOPOLOGY
            | TriMeshFlags::ORIENTED
            | TriMeshFlags::FIX_INTERNAL_EDGES;
        mesh.set_flags(flags).map_err(|e| {
            CoulombError::InvalidParameter(format!(
                "triangle mesh topology (orientation or manifoldness): {e}"
            ))
        })?;
        Ok(Self::new(Repr3::TriangleMesh(mesh)))
    }

    /// A static heightfield over the x-z square `[-sx/2, sx/2] x [-sz/2, sz/2]`: `heights`
    /// (`rows` along z by `cols` along x, row-major, at least 2 x 2) scaled by `scale[1]`;
    /// `scale` finite and > 0.
    pub fn heightfield(rows: usize, cols: usize, heights: &[f64], scale: [f64; 3]) -> Result<Self> {
        if rows < 2 || cols < 2 || heights.len() != rows * cols {
            return Err(CoulombError::Shape(format!(
                "heightfield needs rows, cols >= 2 and rows * cols heights; got {rows} x {cols} \
                 with {} heights",
                heights.len()
            )));
        }
        crate::error::check_finite("heightfield heights", heights)?;
        let s = Vector3::new(
            positive("heightfield scale x", scale[0])?,
            positive("heightfield scale y", scale[1])?,
            positive("heightfield scale z", scale[2])?,
        );
        let h = DMatrix::from_row_slice(rows, cols, heights);
        Ok(Self::new(Repr3::Heightfield(HeightField::with_flags(
            h,
            s,
            HeightFieldFlags::FIX_INTERNAL_EDGES,
        ))))
    }

    /// The half-space `{x : n · x <= 0}` of outward `normal` (finite, nonzero; normalised).
    pub fn half_space(normal: [f64; 3]) -> Result<Self> {
        finite_points("half-space normal", &[normal])?;
        let n = Unit::try_new(Vector3::from(normal), f64::MIN_POSITIVE).ok_or_else(|| {
            CoulombError::InvalidParameter("half-space normal is zero".to_string())
        })?;
        Ok(Self::new(Repr3::HalfSpace(HalfSpace::new(n))))
    }

    fn new(repr: Repr3) -> Self {
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
        self.parry().scale_dyn(&Vector3::repeat(k), 0)
    }

    /// A box's half extents (its polyhedron's corners are at exactly `+-half`), `None` for
    /// other shapes.
    pub fn box_half_extents(&self) -> Option<[f64; 3]> {
        match &self.repr {
            Repr3::Cuboid(_, half) => Some(*half),
            _ => None,
        }
    }

    /// The radius a sphere or a capsule rounds its core by (a point, a segment), 0 for other
    /// shapes: a contact of such a shape is its core point's, moved out by this radius along
    /// the normal (what the stepper's gap curvature follows, module `step::narrow`).
    pub(crate) fn rounding(&self) -> f64 {
        match &self.repr {
            Repr3::Sphere(s) => s.radius,
            Repr3::Capsule(c) => c.radius,
            _ => 0.0,
        }
    }

    /// Which shape this is.
    pub fn kind(&self) -> ShapeKind3 {
        match &self.repr {
            Repr3::Sphere(_) => ShapeKind3::Sphere,
            Repr3::Cuboid(..) => ShapeKind3::Cuboid,
            Repr3::Capsule(_) => ShapeKind3::Capsule,
            Repr3::Cylinder(_) => ShapeKind3::Cylinder,
            Repr3::Cone(_) => ShapeKind3::Cone,
            Repr3::ConvexHull(_) => ShapeKind3::ConvexHull,
            Repr3::Compound(_) => ShapeKind3::Compound,
            Repr3::TriangleMesh(_) => ShapeKind3::TriangleMesh,
            Repr3::Heightfield(_) => ShapeKind3::Heightfield,
            Repr3::HalfSpace(_) => ShapeKind3::HalfSpace,
        }
    }

    /// Whether the shape is static only (mesh, heightfield, half-space): two static shapes
    /// never make a contact.
    pub fn is_static(&self) -> bool {
        matches!(
            self.kind(),
            ShapeKind3::TriangleMesh | ShapeKind3::Heightfield | ShapeKind3::HalfSpace
        )
    }

    fn is_convex(&self) -> bool {
        !self.is_static() && self.kind() != ShapeKind3::Compound
    }

    /// Whether the shape is a half-space (whose contacts parry computes in closed form).
    pub(crate) fn is_half_space(&self) -> bool {
        self.kind() == ShapeKind3::HalfSpace
    }

    /// The parry shape (the narrow phase's boundary).
    pub(crate) fn parry(&self) -> &dyn ParryShape {
        match &self.repr {
            Repr3::Sphere(s) => s,
            Repr3::Cuboid(s, _) => s,
            Repr3::Capsule(s) => s,
            Repr3::Cylinder(s) => s,
            Repr3::Cone(s) => s,
            Repr3::ConvexHull(s) => s,
            Repr3::Compound(s) => s,
            Repr3::TriangleMesh(s) => s,
            Repr3::Heightfield(s) => s,
            Repr3::HalfSpace(s) => s,
        }
    }

    fn shared(&self) -> SharedShape {
        SharedShape(self.parry().clone_dyn().into())
    }

    /// The half diagonal of the shape's bounding box in its frame; `None` for a half-space.
    pub(crate) fn size(&self) -> Option<f64> {
        // a box's bounding box is `[-half, half]` (exactly: its corners), not searched for
        let span = match &self.repr {
            Repr3::Cuboid(_, h) => Vector3::from(*h) * 2.0,
            _ => {
                let b = self.parry().compute_local_aabb();
                b.maxs - b.mins
            }
        };
        let d = 0.5 * span.norm();
        (d.is_finite() && d > 0.0).then_some(d)
    }

    /// The axis-aligned bounding box `(min, max)` of the shape at `pose` (infinite for a
    /// half-space).
    pub fn aabb(&self, pose: &Isometry3<f64>) -> ([f64; 3], [f64; 3]) {
        let b = self.parry().compute_aabb(pose);
        (b.mins.coords.into(), b.maxs.coords.into())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_3d_shapes_are_refused_with_errors() {
        assert!(Shape3::sphere(0.0).is_err());
        assert!(Shape3::sphere(f64::NAN).is_err());
        assert!(Shape3::cuboid([1.0, -1.0, 1.0]).is_err());
        assert!(Shape3::cylinder(1.0, 0.0).is_err());
        assert!(Shape3::cone(f64::INFINITY, 1.0).is_err());
        assert!(Shape3::capsule([0.0; 3], [f64::NAN, 0.0, 0.0], 1.0).is_err());
        // a hull of coplanar points, of too few points, of one repeated point
        let square = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        assert!(Shape3::convex_hull(&square).is_err());
        assert!(Shape3::convex_hull(&square[..2]).is_err());
        assert!(Shape3::convex_hull(&[[1.0; 3]; 5]).is_err());
        assert!(Shape3::compound(&[]).is_err());
        let mesh = Shape3::triangle_mesh(&square, &[[0, 1, 2], [0, 2, 3]]);
        assert!(mesh.is_ok());
        let Ok(mesh) = mesh else { return };
        assert!(Shape3::compound(&[(Isometry3::identity(), mesh)]).is_err());
        assert!(Shape3::triangle_mesh(&square, &[[0, 1, 4]]).is_err());
        assert!(Shape3::triangle_mesh(&square, &[[0, 1, 1]]).is_err());
        let nan = [[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        assert!(matches!(
            Shape3::triangle_mesh(&nan, &[[0, 1, 2]]),
            Err(CoulombError::NonFinite(_))
        ));
        // three triangles on one edge (0, 1)
        let fan = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        assert!(Shape3::triangle_mesh(&fan, &[[0, 1, 2], [0, 1, 3], [0, 1, 4]]).is_err());
        assert!(Shape3::heightfield(1, 2, &[0.0, 0.0], [1.0; 3]).is_err());
        assert!(Shape3::heightfield(2, 2, &[0.0, 0.0, 0.0], [1.0; 3]).is_err());
        assert!(Shape3::heightfield(2, 2, &[0.0, 0.0, 0.0, f64::NAN], [1.0; 3]).is_err());
        assert!(Shape3::heightfield(2, 2, &[0.0; 4], [1.0, 0.0, 1.0]).is_err());
        assert!(Shape3::half_space([0.0; 3]).is_err());
    }

    #[test]
    fn a_mesh_with_adjacent_triangles_wound_opposite_ways_is_refused() {
        let square = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        assert!(Shape3::triangle_mesh(&square, &[[0, 1, 2], [0, 2, 3]]).is_ok());
        assert!(matches!(
            Shape3::triangle_mesh(&square, &[[0, 1, 2], [0, 3, 2]]),
            Err(CoulombError::InvalidParameter(_))
        ));
    }

    /// the box pair's separating-axis test reads the kept half extents instead of the
    /// polyhedron's bounding box: they must be its corners to the bit, at every scale
    #[test]
    fn a_box_keeps_its_polyhedrons_corners_as_half_extents() {
        let mut rng = crate::testing::SplitMix64::new(3);
        for _ in 0..300 {
            let h = [0, 1, 2]
                .map(|_| (1.0 + 9.0 * rng.uniform()) * 10f64.powf(16.0 * rng.uniform() - 8.0));
            let aspect =
                h.iter().fold(0.0f64, |m, &x| m.max(x)) / h.iter().fold(f64::MAX, |m, &x| m.min(x));
            let b = match Shape3::cuboid(h) {
                Ok(b) => b,
                // only a box too thin for its hull is refused
                Err(CoulombError::InvalidParameter(_)) if aspect > 1e12 => continue,
                Err(e) => panic!("box {h:?} (aspect {aspect:.1e}) refused: {e}"),
            };
            let hull = b.parry().compute_local_aabb();
            assert_eq!(b.box_half_extents(), Some(h));
            assert_eq!(hull.maxs.coords, Vector3::from(h), "{h:?}");
            assert_eq!(hull.mins.coords, -Vector3::from(h), "{h:?}");
        }
        assert_eq!(
            Shape3::sphere(1.0).ok().and_then(|s| s.box_half_extents()),
            None
        );
    }

    #[test]
    fn a_box_aabb_at_a_translation_is_the_box() {
        let Ok(b) = Shape3::cuboid([1.0, 2.0, 3.0]) else {
            panic!("valid box")
        };
        let (lo, hi) = b.aabb(&Isometry3::translation(1.0, 1.0, 1.0));
        assert_eq!(lo, [0.0, -1.0, -2.0]);
        assert_eq!(hi, [2.0, 3.0, 4.0]);
    }
}
