//! Geometry: shapes, their contact manifolds, and a broad phase over them; the stepper's
//! solids ([`crate::step::Solid`]) take their contact points from here.
//!
//! The narrow phase is dimforge's parry (`parry3d-f64`, `parry2d-f64`) at version 0.25, the
//! last release line built on nalgebra: from 0.26 on, parry's math is glam. parry 0.25 depends
//! on nalgebra 0.34, the nalgebra of this crate's small blocks, so one nalgebra is in the
//! build and the boundary is a plain type identity: poses go in as nalgebra
//! `Isometry3<f64>` / `Isometry2<f64>`, and the only conversion is that of parry's contact
//! manifolds into [`ContactPoint3`] / [`ContactPoint2`] (in [`contact`]).
//!
//! A contact point between shapes a and b (Stewart 2000, §2; Acary-Brogliato 2008, ch. 3)
//! carries the unit normal `n` from a to b, the signed gap
//!
//! ```text
//!     g = (x_b - x_a) · n,   x_a = q_a ⊕ p_a,  x_b = q_b ⊕ p_b
//! ```
//!
//! (negative when the shapes overlap) and the witness points `p_a`, `p_b` in each body's
//! frame, so that `g` can be re-evaluated at a new pose. A manifold keeps the points with
//! `g <= prediction`. Each point has a [`ContactId`]: the sub-shapes (of a compound, a mesh or
//! a heightfield) and parry's packed feature ids (vertex, edge or face) of the two features
//! that touch. The id depends only on which features touch, so a stepper can carry warm
//! starts and impact memory from one step to the next by matching ids.
//!
//! Where parry's answer is not the contact this crate needs, [`contact`] corrects it and says
//! how: exact recomputation instead of parry's incremental manifold update, a second query
//! pulled apart when shapes touch within rounding (GJK-EPA's wrong depth there), queries in a
//! power-of-two unit near the shapes' size (parry's absolute tolerances), GJK's redundant
//! extra point dropped, and two faces in 3D clipped as polygons along the face's own normal
//! (module `clip`: parry's separate corner and crossing tests could both refuse a corner that
//! two equal faces share to rounding); convex hulls and polygons are searched in the point
//! cloud's principal frame stretched to unit extents (module `hull`: parry's uniform scaling
//! left points of a thin cloud outside its hull), a polyhedron against a half-space is measured
//! at every vertex (parry's support face of a polyhedron need not hold its lowest corner:
//! some hulls just above a floor had no contact at all); boxes are polyhedra (see [`Shape3::cuboid`]), and two
//! boxes touching face to face get their normal and gap from the separating axes, not GJK
//! (module `box_pair`). With a cylinder or a
//! cone, parry builds the manifold from polygonal features picked by a GJK normal of limited
//! accuracy: its deepest gap moves under swap, rigid motion or scaling by up to about 1e-5 of
//! the shapes' size and its normal by about 1e-3 (the tests measure this); with spheres,
//! capsules, boxes, hulls, compounds, meshes, heightfields and half-spaces these invariances
//! hold to rounding.
//!
//! Shapes are built by validating constructors that refuse non-finite data, non-positive
//! sizes and degenerate hulls, meshes and heightfields with a [`crate::CoulombError`] before
//! parry sees them (parry asserts on some of these).

mod box_pair;
pub mod broad;
mod clip;
pub mod contact;
mod convex;
mod crossing;
mod hull;
mod parts;
pub mod shape2;
pub mod shape3;
mod validate;

pub use broad::{AabbBroadPhase, KeptAabbBroadPhase};
pub use contact::{
    contacts2, contacts3, ContactCache2, ContactCache3, ContactId, ContactPoint2, ContactPoint3,
    Reference,
};
pub use shape2::{Shape2, ShapeKind2};
pub use shape3::{Shape3, ShapeKind3};
