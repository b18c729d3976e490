//! Input checks shared by the shape constructors: every refusal is a [`CoulombError`].

use crate::error::{CoulombError, Result};

/// A fresh shape id.
pub(crate) fn next_shape_id() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// `value` finite and > 0.
pub(crate) fn positive(name: &str, value: f64) -> Result<f64> {
    if !value.is_finite() {
        return Err(CoulombError::NonFinite(format!("{name} is {value}")));
    }
    if value <= 0.0 {
        return Err(CoulombError::InvalidParameter(format!(
            "{name} must be > 0, got {value}"
        )));
    }
    Ok(value)
}

/// every coordinate of every point finite.
pub(crate) fn finite_points<const D: usize>(name: &str, points: &[[f64; D]]) -> Result<()> {
    for (k, p) in points.iter().enumerate() {
        if p.iter().any(|x| !x.is_finite()) {
            return Err(CoulombError::NonFinite(format!(
                "{name}: point {k} is {p:?}"
            )));
        }
    }
    Ok(())
}

/// the largest distance between two of `points` (by the bounding box's diagonal, within a
/// factor sqrt(D)), the length scale against which degeneracy is judged.
pub(crate) fn extent<const D: usize>(points: &[[f64; D]]) -> f64 {
    let mut d2 = 0.0;
    for i in 0..D {
        let lo = points.iter().map(|p| p[i]).fold(f64::INFINITY, f64::min);
        let hi = points
            .iter()
            .map(|p| p[i])
            .fold(f64::NEG_INFINITY, f64::max);
        if hi > lo {
            d2 += (hi - lo) * (hi - lo);
        }
    }
    d2.sqrt()
}

fn sub<const D: usize>(a: [f64; D], b: [f64; D]) -> [f64; D] {
    std::array::from_fn(|i| a[i] - b[i])
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm<const D: usize>(a: [f64; D]) -> f64 {
    a.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Relative thickness below which a point set counts as lower-dimensional.
pub(crate) const FLAT: f64 = 1e-9;

/// Whether `points` (finite, at least 4) span 3D: with `L` their extent, some tetrahedron of
/// them has volume `> FLAT L^3` (the far point from the first, the far point from that line,
/// the far point from that plane).
pub(crate) fn spans_3d(points: &[[f64; 3]]) -> bool {
    let scale = extent(points);
    if points.len() < 4 || scale <= 0.0 {
        return false;
    }
    let p0 = points[0];
    let far = |f: &dyn Fn([f64; 3]) -> f64| {
        points
            .iter()
            .copied()
            .max_by(|a, b| f(*a).total_cmp(&f(*b)))
            .unwrap_or(p0)
    };
    let p1 = far(&|p| norm(sub(p, p0)));
    let u = sub(p1, p0);
    let p2 = far(&|p| norm(cross(u, sub(p, p0))));
    let n = cross(u, sub(p2, p0));
    let p3 = far(&|p| {
        let d = sub(p, p0);
        (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]).abs()
    });
    let d = sub(p3, p0);
    let vol6 = (n[0] * d[0] + n[1] * d[1] + n[2] * d[2]).abs();
    vol6 > 6.0 * FLAT * scale * scale * scale
}

/// Whether `points` (finite, at least 3) span 2D: some triangle of them has area
/// `> FLAT L^2`, `L` their extent.
pub(crate) fn spans_2d(points: &[[f64; 2]]) -> bool {
    let scale = extent(points);
    if points.len() < 3 || scale <= 0.0 {
        return false;
    }
    let p0 = points[0];
    let far = |f: &dyn Fn([f64; 2]) -> f64| {
        points
            .iter()
            .copied()
            .max_by(|a, b| f(*a).total_cmp(&f(*b)))
            .unwrap_or(p0)
    };
    let p1 = far(&|p| norm(sub(p, p0)));
    let u = sub(p1, p0);
    let area2 = |p: [f64; 2]| {
        let d = sub(p, p0);
        (u[0] * d[1] - u[1] * d[0]).abs()
    };
    let p2 = far(&area2);
    area2(p2) > 2.0 * FLAT * scale * scale
}

/// Area of triangle (a, b, c) doubled.
pub(crate) fn triangle_area2(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    norm(cross(sub(b, a), sub(c, a)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_unit_cube_spans_3d_and_its_face_does_not() {
        let mut cube = Vec::new();
        for k in 0..8 {
            cube.push([(k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64]);
        }
        assert!(spans_3d(&cube));
        let face: Vec<[f64; 3]> = cube.iter().copied().filter(|p| p[2] == 0.0).collect();
        assert!(!spans_3d(&face));
        // a sliver of relative thickness 1e-12 is flat at every scale
        for s in [1e-4, 1.0, 1e4] {
            let mut sliver: Vec<[f64; 3]> =
                face.iter().map(|p| [p[0] * s, p[1] * s, 0.0]).collect();
            sliver.push([0.5 * s, 0.5 * s, 1e-12 * s]);
            assert!(!spans_3d(&sliver));
        }
    }

    #[test]
    fn collinear_points_do_not_span_2d() {
        let line = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]];
        assert!(!spans_2d(&line));
        assert!(spans_2d(&[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]));
    }

    #[test]
    fn positive_refuses_zero_negative_and_nan() {
        assert!(positive("r", 0.0).is_err());
        assert!(positive("r", -1.0).is_err());
        assert!(matches!(
            positive("r", f64::NAN),
            Err(CoulombError::NonFinite(_))
        ));
        assert_eq!(positive("r", 2.0).ok(), Some(2.0));
    }
}
