//! A generalized-coordinate step whose contact solve is settled by the warm start allocates
//! nothing in the stepper: `M^{-1} G`, W (the one assembly's workspace), q and the impulses are
//! kept from step to step (the system's own callbacks are its business).

use coulomb::error::Result;
use coulomb::step::{GeneralizedStepper, GeneralizedSystem, StepSettings};

mod alloc_count;
use alloc_count::count;

const G: f64 = 9.81;
const A: f64 = 0.5;
const B: f64 = 0.25;

/// a planar box (q = x, y, theta; mass 2) resting on two corners on the floor y = 0.
struct RestingBox;

impl GeneralizedSystem for RestingBox {
    fn dim(&self) -> usize {
        2
    }
    fn nv(&self) -> usize {
        3
    }
    fn laws(&self) -> Vec<(f64, f64)> {
        vec![(0.5, 0.0); 2]
    }
    fn mass(&mut self, _q: &[f64], m: &mut [f64]) -> Result<()> {
        m.fill(0.0);
        m[0] = 2.0;
        m[4] = 2.0;
        m[8] = 2.0 * (4.0 * A * A + 4.0 * B * B) / 12.0;
        Ok(())
    }
    fn force(&mut self, _q: &[f64], _v: &[f64], _t: f64, f: &mut [f64]) -> Result<()> {
        f.copy_from_slice(&[0.0, -2.0 * G, 0.0]);
        Ok(())
    }
    fn contacts(&mut self, q: &[f64], gaps: &mut [f64], rows: &mut [f64]) -> Result<()> {
        let (s, c) = q[2].sin_cos();
        for (k, sx) in [-A, A].into_iter().enumerate() {
            gaps[k] = q[1] + sx * s - B * c;
            let r = &mut rows[k * 6..(k + 1) * 6];
            r.copy_from_slice(&[0.0, 1.0, sx * c + B * s, 1.0, 0.0, -sx * s + B * c]);
        }
        Ok(())
    }
    fn potential(&mut self, q: &[f64]) -> Result<f64> {
        Ok(2.0 * G * q[1])
    }
}

#[test]
fn settled_generalized_steps_allocate_nothing() {
    let steps = 300;
    let settings = StepSettings::new(1e-3, steps);
    let mut st =
        GeneralizedStepper::new(RestingBox, &[0.0, B, 0.0], &[0.0; 3], &settings).expect("valid");
    let mut contacts = st.records();
    contacts.reserve(4 * steps);
    let (mut settled, mut quiet) = (0, 0);
    for k in 0..steps {
        let before = count();
        let rec = st.step(&mut contacts).expect("solved");
        let allocations = count() - before;
        assert_eq!(rec.active, 2, "step {k}");
        if k >= 10 && rec.iterations == 0 {
            settled += 1;
            if allocations == 0 {
                quiet += 1;
            }
        }
    }
    assert!(settled > steps / 3, "{settled} settled steps");
    assert_eq!(quiet, settled, "settled steps that allocated");
    // resting: the box has not moved
    assert!(st.q[1] - B > -1e-9 && st.q[0].abs() < 1e-12, "{:?}", st.q);
}
