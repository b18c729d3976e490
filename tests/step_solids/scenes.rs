//! Scenes of solids for the stepper's tests.
#![allow(dead_code)]

use coulomb::geometry::{Shape2, Shape3};
use coulomb::step::{Body, BodyKind, HalfSpace, Pair, Scene, Solid, SolidShape};

pub const G: f64 = 9.81;

pub fn ok<T>(r: coulomb::Result<T>) -> T {
    match r {
        Ok(v) => v,
        Err(e) => panic!("unexpected error: {e}"),
    }
}

/// the identity pose of a scene of dimension `dim`.
pub fn identity(dim: usize) -> Vec<f64> {
    if dim == 2 {
        vec![0.0; 3]
    } else {
        vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
    }
}

/// a box (2D: the rectangle of the half sides along x and the vertical, `half[2]`) as a
/// solid shape.
pub fn box_shape(dim: usize, half: [f64; 3]) -> SolidShape {
    if dim == 2 {
        SolidShape::Planar(ok(Shape2::rectangle([half[0], half[2]])))
    } else {
        SolidShape::Spatial(ok(Shape3::cuboid(half)))
    }
}

/// a static solid at the pose `pose`.
pub fn static_solid(shape: SolidShape) -> Solid {
    let dim = match shape {
        SolidShape::Planar(_) => 2,
        SolidShape::Spatial(_) => 3,
    };
    Solid {
        body: None,
        pose: identity(dim),
        shape,
    }
}

/// a solid on body `body` at the body's frame.
pub fn on_body(body: usize, shape: SolidShape) -> Solid {
    let mut s = static_solid(shape);
    s.body = Some(body);
    s
}

/// a rigid body of a box's inertia: `q` its coordinates, `v` its velocities.
pub fn box_body(dim: usize, m: f64, half: [f64; 3], q0: Vec<f64>, v0: Vec<f64>) -> Body {
    let [a, b, c] = half.map(|x| 2.0 * x);
    if dim == 2 {
        Body {
            kind: BodyKind::Planar,
            mass: m,
            inertia: vec![m * (a * a + c * c) / 12.0],
            q0,
            v0,
            force: vec![0.0; 2],
        }
    } else {
        let mut j = vec![0.0; 9];
        j[0] = m * (b * b + c * c) / 12.0;
        j[4] = m * (a * a + c * c) / 12.0;
        j[8] = m * (a * a + b * b) / 12.0;
        Body {
            kind: BodyKind::Spatial,
            mass: m,
            inertia: j,
            q0,
            v0,
            force: vec![0.0; 3],
        }
    }
}

/// coordinates at height `z` (the last axis) and x, no rotation.
pub fn at(dim: usize, x: f64, z: f64) -> Vec<f64> {
    if dim == 2 {
        vec![x, z, 0.0]
    } else {
        vec![x, 0.0, z, 1.0, 0.0, 0.0, 0.0]
    }
}

/// velocities: `vx` along x.
pub fn moving(dim: usize, vx: f64) -> Vec<f64> {
    let mut v = vec![0.0; if dim == 2 { 3 } else { 6 }];
    v[0] = vx;
    v
}

pub fn gravity(dim: usize) -> Vec<f64> {
    let mut g = vec![0.0; dim];
    g[dim - 1] = -G;
    g
}

pub fn floor(dim: usize) -> HalfSpace {
    let mut n = vec![0.0; dim];
    n[dim - 1] = 1.0;
    HalfSpace {
        point: vec![0.0; dim],
        normal: n,
    }
}

/// A box (half sides `(0.1, 0.07, 0.05) s`) sliding at `v0` along x on a long box (half
/// sides `(2, 2, 0.1) s`, its top face at height 0 when static, at `0.2 s` when it is a body
/// resting on the floor with friction 1).
pub fn box_on_box(dim: usize, s: f64, mu: f64, v0: f64, lower_is_body: bool) -> Scene {
    let top = [0.1 * s, 0.07 * s, 0.05 * s];
    let low = [2.0 * s, 2.0 * s, 0.1 * s];
    let (tz, mut bodies, mut solids, mut pairs) = (0.0, vec![], vec![], vec![]);
    let mut base = tz;
    if lower_is_body {
        bodies.push(box_body(
            dim,
            5.0,
            low,
            at(dim, 0.0, low[2]),
            moving(dim, 0.0),
        ));
        solids.push(on_body(0, box_shape(dim, low)));
        pairs.push(Pair::SolidHalfSpace {
            solid: 0,
            half_space: 0,
            mu: 1.0,
            e: 0.0,
        });
        base = 2.0 * low[2];
    } else {
        let mut s = static_solid(box_shape(dim, low));
        s.pose[dim - 1] = -low[2];
        solids.push(s);
    }
    let ib = bodies.len();
    bodies.push(box_body(
        dim,
        1.0,
        top,
        at(dim, 0.0, base + top[2]),
        moving(dim, v0),
    ));
    solids.push(on_body(ib, box_shape(dim, top)));
    pairs.push(Pair::SolidSolid {
        a: 1,
        b: 0,
        mu,
        e: 0.0,
    });
    Scene {
        dim,
        gravity: gravity(dim),
        bodies,
        shapes: vec![],
        half_spaces: vec![floor(dim)],
        pairs,
        solids,
    }
}

/// One body carrying `shape`, at `q0`, against the floor with friction `mu`.
pub fn one_solid_on_floor(dim: usize, shape: SolidShape, q0: Vec<f64>, mu: f64) -> Scene {
    let body = box_body(dim, 1.0, [0.1, 0.1, 0.1], q0, moving(dim, 0.0));
    Scene {
        dim,
        gravity: gravity(dim),
        bodies: vec![body],
        shapes: vec![],
        half_spaces: vec![floor(dim)],
        pairs: vec![Pair::SolidHalfSpace {
            solid: 0,
            half_space: 0,
            mu,
            e: 0.0,
        }],
        solids: vec![on_body(0, shape)],
    }
}

/// round shapes resting on the floor: (dim, shape, coordinates).
pub fn resting_round_shapes() -> Vec<(usize, SolidShape, Vec<f64>)> {
    let r = 0.05;
    let (c, s) = (
        std::f64::consts::FRAC_PI_4.cos(),
        std::f64::consts::FRAC_PI_4.sin(),
    );
    vec![
        (
            3,
            SolidShape::Spatial(ok(Shape3::capsule([-0.2, 0.0, 0.0], [0.2, 0.0, 0.0], r))),
            at(3, 0.0, r),
        ),
        // a cylinder's axis is its y: lying on its side
        (
            3,
            SolidShape::Spatial(ok(Shape3::cylinder(0.2, r))),
            at(3, 0.0, r),
        ),
        // standing on its base (y turned to z)
        (
            3,
            SolidShape::Spatial(ok(Shape3::cylinder(0.2, r))),
            vec![0.0, 0.0, 0.2, c, s, 0.0, 0.0],
        ),
        (
            2,
            SolidShape::Planar(ok(Shape2::capsule([-0.2, 0.0], [0.2, 0.0], r))),
            at(2, 0.0, r),
        ),
    ]
}

/// `n` boxes of half side `half` stacked on the floor (the broad phase finds the pairs).
pub fn tower(dim: usize, n: usize, half: f64, mu: f64) -> Scene {
    let h3 = [half; 3];
    let bodies = (0..n)
        .map(|k| {
            box_body(
                dim,
                1.0,
                h3,
                at(dim, 0.0, half * (2 * k + 1) as f64),
                moving(dim, 0.0),
            )
        })
        .collect();
    let solids = (0..n).map(|k| on_body(k, box_shape(dim, h3))).collect();
    Scene {
        dim,
        gravity: gravity(dim),
        bodies,
        shapes: vec![],
        half_spaces: vec![floor(dim)],
        pairs: vec![
            Pair::Solids { mu, e: 0.0 },
            Pair::SolidHalfSpace {
                solid: 0,
                half_space: 0,
                mu,
                e: 0.0,
            },
        ],
        solids,
    }
}

/// A box of half sides (0.1, 0.06, 0.04) turned by `tilt` (2D: the angle; 3D: about x,
/// then about y), its lowest corner 0.05 m above a static box's top face (height 0),
/// frictionless, restitution `e`.
pub fn dropped_box(dim: usize, tilt: [f64; 2], e: f64) -> Scene {
    let half = [0.1, 0.06, 0.04];
    let low = [1.0, 1.0, 0.1];
    let (q0, lowest) = if dim == 2 {
        let (s, c) = tilt[0].sin_cos();
        let lowest = -(half[0] * s).abs() - (half[2] * c).abs();
        (vec![0.0, 0.05 - lowest, tilt[0]], lowest)
    } else {
        let rx = nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::x_axis(), tilt[0]);
        let ry = nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::y_axis(), tilt[1]);
        let q = ry * rx;
        let r = q.to_rotation_matrix();
        let mut lowest = f64::INFINITY;
        for k in 0..8 {
            let sgn = |b: usize| if k & b == 0 { -1.0 } else { 1.0 };
            let p =
                r * nalgebra::Vector3::new(sgn(1) * half[0], sgn(2) * half[1], sgn(4) * half[2]);
            lowest = lowest.min(p[2]);
        }
        (vec![0.0, 0.0, 0.05 - lowest, q.w, q.i, q.j, q.k], lowest)
    };
    let _ = lowest;
    let mut lower = static_solid(box_shape(dim, low));
    lower.pose[dim - 1] = -low[2];
    Scene {
        dim,
        gravity: gravity(dim),
        bodies: vec![box_body(dim, 1.0, half, q0, moving(dim, 0.0))],
        shapes: vec![],
        half_spaces: vec![],
        pairs: vec![Pair::SolidSolid {
            a: 0,
            b: 1,
            mu: 0.0,
            e,
        }],
        solids: vec![on_body(0, box_shape(dim, half)), lower],
    }
}

/// A flat triangle mesh over `[-half, half]^2` at z = 0: `n x n` square cells of two
/// triangles each, wound so that the normals are +z.
pub fn flat_mesh(n: u32, half: f64) -> Shape3 {
    let mut verts = vec![];
    for i in 0..=n {
        for j in 0..=n {
            let f = |k: u32| -half + 2.0 * half * k as f64 / n as f64;
            verts.push([f(i), f(j), 0.0]);
        }
    }
    let mut tris = vec![];
    for i in 0..n {
        for j in 0..n {
            let (a, b) = (i * (n + 1) + j, (i + 1) * (n + 1) + j);
            tris.push([a, b, b + 1]);
            tris.push([a, b + 1, a + 1]);
        }
    }
    ok(Shape3::triangle_mesh(&verts, &tris))
}
