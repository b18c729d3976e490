//! A scene's description (the dict of plain lists `coulomb.model.Scene` builds) read into the
//! core's [`Scene`], and a solid's description checked alone.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use super::super::to_py;
use crate::error::CoulombError;
use crate::geometry::{Shape2, Shape3};
use crate::step::{Body, BodyKind, HalfSpace, Pair, Scene, Shape, Solid, SolidShape};

pub(super) fn item<'py, T: FromPyObjectOwned<'py>>(
    d: &Bound<'py, PyDict>,
    key: &str,
) -> PyResult<T> {
    match d.get_item(key)? {
        Some(v) => v.extract::<T>().map_err(|e| {
            let e: PyErr = e.into();
            to_py(
                d.py(),
                CoulombError::Shape(format!("scene entry {key:?} has the wrong type: {e}")),
            )
        }),
        None => Err(to_py(
            d.py(),
            CoulombError::Shape(format!("scene entry {key:?} is missing")),
        )),
    }
}

pub(super) fn dicts<'py>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let list: Bound<'py, PyList> = item(d, key)?;
    list.iter()
        .map(|x| {
            x.cast_into::<PyDict>().map_err(|_| {
                to_py(
                    d.py(),
                    CoulombError::Shape(format!("scene entry {key:?} must be a list of dicts")),
                )
            })
        })
        .collect()
}

pub(super) fn scene_from_dict(d: &Bound<'_, PyDict>) -> PyResult<Scene> {
    let py = d.py();
    let mut bodies = vec![];
    for b in dicts(d, "bodies")? {
        let kind: String = item(&b, "kind")?;
        let kind = match kind.as_str() {
            "particle" => BodyKind::Particle,
            "planar" => BodyKind::Planar,
            "spatial" => BodyKind::Spatial,
            other => {
                return Err(to_py(
                    py,
                    CoulombError::InvalidParameter(format!("unknown body kind {other:?}")),
                ))
            }
        };
        bodies.push(Body {
            kind,
            mass: item(&b, "mass")?,
            inertia: item(&b, "inertia")?,
            q0: item(&b, "q0")?,
            v0: item(&b, "v0")?,
            force: item(&b, "force")?,
        });
    }
    let mut shapes = vec![];
    for s in dicts(d, "shapes")? {
        shapes.push(Shape {
            body: item(&s, "body")?,
            points: item(&s, "points")?,
            radius: item(&s, "radius")?,
        });
    }
    let mut half_spaces = vec![];
    for s in dicts(d, "half_spaces")? {
        half_spaces.push(HalfSpace {
            point: item(&s, "point")?,
            normal: item(&s, "normal")?,
        });
    }
    let mut pairs = vec![];
    for p in dicts(d, "pairs")? {
        let kind: String = item(&p, "kind")?;
        let (mu, e): (f64, f64) = (item(&p, "mu")?, item(&p, "e")?);
        if kind == "spheres" {
            // every sphere pair, found by the stepper's broad phase: no indices
            pairs.push(Pair::Spheres { mu, e });
            continue;
        }
        if kind == "solids" {
            pairs.push(Pair::Solids { mu, e });
            continue;
        }
        let (a, b): (usize, usize) = (item(&p, "a")?, item(&p, "b")?);
        pairs.push(match kind.as_str() {
            "half_space" => Pair::ShapeHalfSpace {
                shape: a,
                half_space: b,
                mu,
                e,
            },
            "sphere" => Pair::SphereSphere { a, b, mu, e },
            "solid" => Pair::SolidSolid { a, b, mu, e },
            "solid_half_space" => Pair::SolidHalfSpace {
                solid: a,
                half_space: b,
                mu,
                e,
            },
            other => {
                return Err(to_py(
                    py,
                    CoulombError::InvalidParameter(format!("unknown pair kind {other:?}")),
                ))
            }
        });
    }
    let dim: usize = item(d, "dim")?;
    let mut solids = vec![];
    if d.get_item("solids")?.is_some() {
        for s in dicts(d, "solids")? {
            solids.push(Solid {
                body: item(&s, "body")?,
                pose: item(&s, "pose")?,
                shape: solid_shape(&s, dim).map_err(|e| to_py(py, e))?,
            });
        }
    }
    Ok(Scene {
        dim,
        gravity: item(d, "gravity")?,
        bodies,
        shapes,
        half_spaces,
        pairs,
        solids,
    })
}

/// a solid's shape from its dict (`kind` and the shape's data), built by the geometry
/// layer's validating constructors.
fn solid_shape(s: &Bound<'_, PyDict>, dim: usize) -> Result<SolidShape, CoulombError> {
    let get = |key: &str| -> Result<Bound<'_, PyAny>, CoulombError> {
        s.get_item(key)
            .ok()
            .flatten()
            .ok_or_else(|| CoulombError::Shape(format!("solid entry {key:?} is missing")))
    };
    fn ex<'py, T: FromPyObjectOwned<'py>>(
        v: Bound<'py, PyAny>,
        key: &str,
    ) -> Result<T, CoulombError> {
        v.extract::<T>()
            .map_err(|_| CoulombError::Shape(format!("solid entry {key:?} has the wrong type")))
    }
    let kind: String = ex(get("kind")?, "kind")?;
    if dim == 2 {
        return Ok(SolidShape::Planar(shape2(s, &kind)?));
    }
    Ok(SolidShape::Spatial(shape3(s, &kind)?))
}

/// a 2D shape from a solid's dict (a compound's parts recursively).
fn shape2(s: &Bound<'_, PyDict>, kind: &str) -> Result<Shape2, CoulombError> {
    fn ex<'py, T: FromPyObjectOwned<'py>>(
        s: &Bound<'py, PyDict>,
        key: &str,
    ) -> Result<T, CoulombError> {
        s.get_item(key)
            .ok()
            .flatten()
            .ok_or_else(|| CoulombError::Shape(format!("solid entry {key:?} is missing")))?
            .extract::<T>()
            .map_err(|_| CoulombError::Shape(format!("solid entry {key:?} has the wrong type")))
    }
    let f = |key: &str| -> Result<f64, CoulombError> { ex(s, key) };
    let p2 = |key: &str| -> Result<[f64; 2], CoulombError> { ex(s, key) };
    Ok(match kind {
        "disk" | "sphere" => Shape2::disk(f("radius")?)?,
        "box" => Shape2::rectangle(p2("half_extents")?)?,
        "polygon" | "convex_hull" => {
            let pts: Vec<[f64; 2]> = ex(s, "points")?;
            Shape2::convex_polygon(&pts)?
        }
        "segment" => Shape2::segment(p2("a")?, p2("b")?)?,
        "capsule" => Shape2::capsule(p2("a")?, p2("b")?, f("radius")?)?,
        "polyline" => {
            let v: Vec<[f64; 2]> = ex(s, "vertices")?;
            Shape2::polyline(&v)?
        }
        "compound" => {
            let parts: Vec<Bound<'_, PyDict>> = ex(s, "parts")?;
            let mut out = Vec::with_capacity(parts.len());
            for p in &parts {
                let k: String = ex(p, "kind")?;
                let pose: Vec<f64> = ex(p, "pose")?;
                if pose.len() != 3 {
                    return Err(CoulombError::Shape(format!(
                        "a 2D compound part's pose has {} entries, expected 3",
                        pose.len()
                    )));
                }
                crate::error::check_finite("compound part pose", &pose)?;
                let iso =
                    nalgebra::Isometry2::new(nalgebra::Vector2::new(pose[0], pose[1]), pose[2]);
                out.push((iso, shape2(p, &k)?));
            }
            Shape2::compound(&out)?
        }
        other => {
            return Err(CoulombError::InvalidParameter(format!(
                "no 2D solid of kind {other:?}"
            )))
        }
    })
}

/// a 3D shape from a solid's dict (a compound's parts recursively).
fn shape3(s: &Bound<'_, PyDict>, kind: &str) -> Result<Shape3, CoulombError> {
    fn ex<'py, T: FromPyObjectOwned<'py>>(
        s: &Bound<'py, PyDict>,
        key: &str,
    ) -> Result<T, CoulombError> {
        s.get_item(key)
            .ok()
            .flatten()
            .ok_or_else(|| CoulombError::Shape(format!("solid entry {key:?} is missing")))?
            .extract::<T>()
            .map_err(|_| CoulombError::Shape(format!("solid entry {key:?} has the wrong type")))
    }
    let f = |key: &str| -> Result<f64, CoulombError> { ex(s, key) };
    let p3 = |key: &str| -> Result<[f64; 3], CoulombError> { ex(s, key) };
    Ok(match kind {
        "sphere" => Shape3::sphere(f("radius")?)?,
        "box" => Shape3::cuboid(p3("half_extents")?)?,
        "capsule" => Shape3::capsule(p3("a")?, p3("b")?, f("radius")?)?,
        "cylinder" => Shape3::cylinder(f("half_height")?, f("radius")?)?,
        "cone" => Shape3::cone(f("half_height")?, f("radius")?)?,
        "convex_hull" => {
            let pts: Vec<[f64; 3]> = ex(s, "points")?;
            Shape3::convex_hull(&pts)?
        }
        "triangle_mesh" => {
            let v: Vec<[f64; 3]> = ex(s, "vertices")?;
            let t: Vec<[u32; 3]> = ex(s, "triangles")?;
            Shape3::triangle_mesh(&v, &t)?
        }
        "heightfield" => {
            let rows: usize = ex(s, "rows")?;
            let cols: usize = ex(s, "cols")?;
            let h: Vec<f64> = ex(s, "heights")?;
            Shape3::heightfield(rows, cols, &h, p3("scale")?)?
        }
        "compound" => {
            let parts: Vec<Bound<'_, PyDict>> = ex(s, "parts")?;
            let mut out = Vec::with_capacity(parts.len());
            for p in &parts {
                let k: String = ex(p, "kind")?;
                let pose: Vec<f64> = ex(p, "pose")?;
                if pose.len() != 7 {
                    return Err(CoulombError::Shape(format!(
                        "a compound part's pose has {} entries, expected 7",
                        pose.len()
                    )));
                }
                crate::error::check_finite("compound part pose", &pose)?;
                let q = nalgebra::Quaternion::new(pose[3], pose[4], pose[5], pose[6]);
                if q.norm() == 0.0 {
                    return Err(CoulombError::InvalidParameter(
                        "a compound part's orientation is zero".into(),
                    ));
                }
                let iso = nalgebra::Isometry3::from_parts(
                    nalgebra::Translation3::new(pose[0], pose[1], pose[2]),
                    nalgebra::UnitQuaternion::from_quaternion(q),
                );
                out.push((iso, shape3(p, &k)?));
            }
            Shape3::compound(&out)?
        }
        other => {
            return Err(CoulombError::InvalidParameter(format!(
                "no 3D solid of kind {other:?}"
            )))
        }
    })
}

/// Checks a solid's description (a dict as in a scene's `solids`) by building its shape:
/// the geometry layer's errors (a hull of coplanar points, a non-manifold mesh, a zero size)
/// as `coulomb.errors` exceptions, before any step.
#[pyfunction]
pub(super) fn solid_check(solid: &Bound<'_, PyDict>, dim: usize) -> PyResult<()> {
    let py = solid.py();
    if dim != 2 && dim != 3 {
        return Err(to_py(
            py,
            CoulombError::InvalidParameter(format!("dim must be 2 or 3, got {dim}")),
        ));
    }
    solid_shape(solid, dim)
        .map(|_| ())
        .map_err(|e| to_py(py, e))
}
