//! Shapes made of parts (compounds of convex shapes, static triangle meshes and heightfields)
//! against convex shapes, half-spaces and each other, pair of parts by pair of parts through
//! the convex construction of module `convex` (a polyhedron's face whole, a round cap as its
//! inscribed polygon, faces clipped by module `clip`).
//!
//! parry's composite paths take every pair of parts through its own convex-convex manifold,
//! which keeps 4 corners of a face: an octagonal prism's face on a mesh's triangle, or a
//! cylinder's base, touched at 4 points, its support polygon short of the face.
//!
//! A mesh's or a heightfield's triangle carries the pseudo-normals of its edges (the meshes are
//! built with parry's `FIX_INTERNAL_EDGES`): the contact normal a triangle may give is projected
//! into the cone they allow, or the triangle gives no contact, so that a body sliding across
//! the mesh's shared edges is not stopped by the edges' normals ("internal edges": parry's
//! normal constraints, applied here as parry applies them).

use nalgebra::Isometry3;
use parry3d_f64::bounding_volume::{Aabb, BoundingVolume as _};
use parry3d_f64::query::details::NormalConstraints;
use parry3d_f64::query::{ContactManifold, PersistentQueryDispatcher as _};
use parry3d_f64::shape::{Compound, HeightField, Shape, ShapeType, TriMesh, TrianglePseudoNormals};

use super::contact::Reference;
use super::convex::{convex3, handles3, one3, Convex3};

type Manifold = ContactManifold<Reference, ()>;

/// One shape of a pair, as the parts it is made of.
#[derive(Clone, Copy)]
enum Side<'a> {
    /// a convex shape or a half-space: one part, itself.
    Whole(&'a dyn Shape),
    Compound(&'a Compound),
    Mesh(&'a TriMesh),
    Heightfield(&'a HeightField),
}

impl<'a> Side<'a> {
    /// `s` as parts, `None` for a shape of none of these kinds.
    fn of(s: &'a dyn Shape) -> Option<Self> {
        if let Some(c) = s.as_compound() {
            Some(Self::Compound(c))
        } else if let Some(m) = s.as_trimesh() {
            Some(Self::Mesh(m))
        } else if let Some(h) = s.as_heightfield() {
            Some(Self::Heightfield(h))
        } else if s.is_convex() || s.shape_type() == ShapeType::HalfSpace {
            Some(Self::Whole(s))
        } else {
            None
        }
    }

    /// Calls `each(part, pose, shape, constraints)` for every part whose bounding box (in
    /// this shape's frame) meets `aabb`: the part's index (a compound's part, a mesh's or a
    /// heightfield's triangle; 0 for a whole shape), its pose in the shape's frame (`None`: the
    /// shape's own frame), the part, and a triangle's normal constraints. Stops, returning
    /// `false`, when `each` does.
    fn each_part(
        &self,
        aabb: &Aabb,
        each: &mut impl FnMut(
            u32,
            Option<Isometry3<f64>>,
            &dyn Shape,
            Option<&dyn NormalConstraints>,
        ) -> bool,
    ) -> bool {
        match *self {
            Self::Whole(s) => each(0, None, s, None),
            Self::Compound(c) => c.shapes().iter().enumerate().all(|(k, (pose, part))| {
                !part.compute_aabb(pose).intersects(aabb)
                    || each(k as u32, Some(*pose), &**part, None)
            }),
            Self::Mesh(m) => m.bvh().intersect_aabb(aabb).all(|id| {
                // the tree may name padding leaves past the last triangle
                if id >= m.num_triangles() as u32 {
                    return true;
                }
                let normals = m.triangle_normal_constraints(id);
                each(id, None, &m.triangle(id), constraints(&normals))
            }),
            Self::Heightfield(h) => {
                let mut going = true;
                h.map_elements_in_local_aabb(aabb, &mut |id, tri| {
                    if going {
                        let normals = h.triangle_normal_constraints(id);
                        going = each(id, None, tri, constraints(&normals));
                    }
                });
                going
            }
        }
    }
}

/// [`convex3`] for two convex shapes (or one and a half-space); otherwise, where either shape
/// is made of parts (module docs), every pair of parts whose bounding boxes (grown by the
/// prediction) meet gets its manifold from [`convex3`]'s construction where it applies, from
/// parry's convex-convex manifold otherwise (balls, two capsules), with the triangles' normal
/// constraints, each into its own manifold. `false`, with `manifolds` untouched, for a pair
/// neither handles.
pub(super) fn convex3_or_parts(
    pos12: &Isometry3<f64>,
    a: &dyn Shape,
    b: &dyn Shape,
    pn: (f64, f64),
    manifolds: &mut Vec<Manifold>,
    ws: &mut Convex3,
) -> bool {
    let (Some(sa), Some(sb)) = (Side::of(a), Side::of(b)) else {
        return false;
    };
    if let (Side::Whole(_), Side::Whole(_)) = (sa, sb) {
        return convex3(pos12, a, b, pn, manifolds, ws);
    }
    let prediction = pn.0;
    let pos21 = pos12.inverse();
    // b's bounding box in a's frame: a's parts away from it are skipped before any pairing
    let whole_b = b.compute_aabb(pos12).loosened(prediction);
    let mut used = 0;
    let done = sa.each_part(&whole_b, &mut |ia, pa, part_a, nc_a| {
        let pose_a = pa.unwrap_or_else(Isometry3::identity);
        // the part's bounding box in b's frame
        let near_a = part_a.compute_aabb(&(pos21 * pose_a)).loosened(prediction);
        sb.each_part(&near_a, &mut |ib, pb, part_b, nc_b| {
            let pose = pose_a.inv_mul(&(pos12 * pb.unwrap_or_else(Isometry3::identity)));
            if used == manifolds.len() {
                manifolds.push(Manifold::new());
            }
            let m = &mut manifolds[used];
            used += 1;
            m.points.clear();
            (m.subshape1, m.subshape2) = (ia, ib);
            (m.subshape_pos1, m.subshape_pos2) = (pa, pb);
            if handles3(part_a, part_b) {
                one3(&pose, part_a, part_b, pn, m, ws, (nc_a, nc_b))
            } else {
                parry3d_f64::query::DefaultQueryDispatcher
                    .contact_manifold_convex_convex(
                        &pose, part_a, part_b, nc_a, nc_b, prediction, m,
                    )
                    .is_ok()
            }
        })
    });
    if !done {
        return false;
    }
    for m in &mut manifolds[used..] {
        m.points.clear();
    }
    true
}

/// A triangle's pseudo-normals as the constraints [`one3`] takes.
fn constraints(n: &Option<TrianglePseudoNormals>) -> Option<&dyn NormalConstraints> {
    n.as_ref().map(|n| n as &dyn NormalConstraints)
}
