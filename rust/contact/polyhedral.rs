//! The polyhedral-cone (Stewart-Trinkle) contact LCP, solved by Lemke's method: the friction
//! disk replaced by a polygon of tangent directions, friction selected by complementarity, and
//! the inelastic step written as one LCP (Stewart and Trinkle 1996; Stewart 2000).
//!
//! Per frictional contact i (`mu_i > 0`) the friction disk is replaced by the polygon spanned
//! by `s` unit tangent directions in ± pairs, `D_i = [d_1 … d_s]`, with
//! `d_k = (cos 2πk/s, sin 2πk/s)` in 3D (`s` even, `>= 4`) and `D_i = [1, -1]` in 2D (`s = 2`,
//! where the polygon *is* the interval, so the answer is exact):
//!
//! ```text
//!     r_t = D β,   β >= 0,   1^T β <= mu r_n,
//!     0 <= β ⊥ D^T u_t + λ 1 >= 0,     0 <= λ ⊥ mu r_n - 1^T β >= 0.
//! ```
//!
//! With `z = (r_n (nc), β (Σ s_i), λ (one per frictional contact))` and W split into its
//! normal and tangential rows this is `0 <= z ⊥ A z + b >= 0` with
//!
//! ```text
//!     A = [ W_nn      W_nt D      0 ]        b = [ q_n     ]
//!         [ D^T W_tn  D^T W_tt D  E ]            [ D^T q_t ]
//!         [ mu        -E^T        0 ]            [ 0       ]
//! ```
//!
//! (E: each contact's β block to its λ).
//!
//! As written, A mixes units: its W blocks are velocity per impulse, the λ column and the
//! last row are pure numbers (mu, ±1), and b holds velocities and zeros. Lemke's pivot
//! tolerances are relative to the entries, so with W and q of order 1e-10 the λ column looked
//! like the large entries and the W blocks like rounding: friction was dropped (r = (6, 0) for
//! the chapter's inelastic step scaled by 1e-10, instead of (6, -1.2)). The LCP is therefore
//! assembled in balanced units: per frictional contact, with `c_i = 1 / rho_i` its normal stiffness
//! `W_nn,i` (the scale of [`super::measures`]), the λ column is multiplied by `c_i` and the last
//! row too,
//!
//! ```text
//!     [ mu c_i   -c_i E^T   0 ],     λ column c_i E,     z_λ = λ / c_i,
//! ```
//!
//! a positive scaling of one row and one column, which leaves the complementarity problem
//! unchanged (`λ = c_i z_λ` is still the sliding speed) while every entry of A now scales as W
//! does: changing the impulse and velocity units scales A and b as a whole, which Lemke's
//! scale-aware tests do not see.
//!
//! Anisotropic friction (3D, the ellipse `(r_t1 / mu_1)^2 + (r_t2 / mu_2)^2 <= r_n^2`): the
//! directions of contact i are scaled along the tangents,
//! `d_k = (mu_1 cos θ_k, mu_2 sin θ_k) / m` with `m = max(mu_1, mu_2) = mu_i` in the row
//! `m r_n - 1^T β`, so the polygon's vertices `m r_n d_k = r_n (mu_1 cos θ_k, mu_2 sin θ_k)` lie
//! on the ellipse: the polygon is inscribed in it, as the isotropic one is in the disk, and
//! the rest of the LCP is unchanged. The reported measures are then taken against the exact
//! ellipse.
//!
//! With friction coefficients of 1e8 and more the LCP is conditioned like mu and whether a
//! pivoting path solves it depends on the rounding of the data; when every path fails, two
//! reformulations without mu's size in the tableau are tried, the cone rows capped (sticking
//! contacts) and sliding contacts' β in units of r_n, and an answer of either is kept only when
//! it is an answer of the given LCP (`polyhedral_large_mu.rs`).
//!
//! A is copositive but not positive semidefinite, so
//! the LCP is solved by [`crate::lcp::solve_lemke`], not by PGS. Frictionless contacts carry
//! only their normal unknown. The impulses are mapped back (`r_i = (r_n, D_i β_i)`) and the
//! velocity `u = W r + q` is recomputed from the original W and q.
//!
//! The reported [`super::ContactMeasures`] are the same natural-map measures as NSGS, i.e.
//! measured against the *exact* friction disk. In 3D the polyhedral answer is an
//! approximation: a sliding contact's impulse snaps to a facet, so the measures there reflect
//! the facet error (they shrink as `s` grows, not monotonically). Success in 3D therefore
//! means that the polyhedral LCP was solved by Lemke's rule (its literature error and its
//! unit-free error within the tolerance); the LCP's own error is in the message. In 2D the
//! polygon is exact and success is the rule of every contact method,
//! [`super::ContactMeasures::passes`] on the impulses. In either dimension, impulses that pass
//! that rule are a solution even where Lemke's own certificate failed (a badly scaled LCP,
//! bodies of very different masses).

use super::{measure_into, ContactProblem, ContactSolution};
use crate::error::{CoulombError, Result};
use crate::lcp::{
    measure as measure_lcp, solve_lemke, LcpRef, LcpSolution, LcpStatus, LemkeEngine,
    LemkeSettings, WarmStart,
};
use crate::readable::Readable;

/// Settings of [`solve_polyhedral`].
#[derive(Clone, Debug)]
pub struct PolyhedralSettings {
    /// tangent directions per frictional contact, in ± pairs: even and `>= 4` in 3D; exactly 2
    /// in 2D (the only meaningful choice there, and exact).
    pub facets: usize,
    /// the settings of the Lemke solve of the LCP.
    pub lemke: LemkeSettings,
}

impl PolyhedralSettings {
    /// the default for a dimension: 8 facets in 3D, 2 in 2D, default Lemke settings.
    pub fn for_dim(dim: usize) -> Self {
        Self {
            facets: if dim == 2 { 2 } else { 8 },
            lemke: LemkeSettings::default(),
        }
    }
}

/// The assembled polyhedral LCP `0 <= z ⊥ m z + q >= 0` of a contact problem, with the layout
/// of z (see the module notes).
#[derive(Clone, Debug)]
pub struct PolyhedralLcp {
    /// the number of LCP unknowns, `nc + Σ s_i + (frictional contacts)`.
    pub n: usize,
    /// A, row-major, `n * n` entries.
    pub m: Vec<f64>,
    /// b, `n` entries.
    pub q: Vec<f64>,
    /// contact components (`dim`).
    dim: usize,
    /// the tangent directions, `facets` pairs `(d_x, d_y)` (`d_y = 0` in 2D).
    directions: Vec<[f64; 2]>,
    /// per contact, the scale of the directions along each tangent: `(1, 1)`, or
    /// `(mu_1 / m, mu_2 / m)` for anisotropic friction.
    scale: Vec<[f64; 2]>,
    /// per contact, the index of its first β in z (`None` when frictionless).
    beta: Vec<Option<usize>>,
    /// per contact, the index of its λ in z (`None` when frictionless).
    lambda: Vec<Option<usize>>,
    /// per contact, the unit `c_i` of its λ column and last row (see the module notes).
    unit: Vec<f64>,
    /// per contact, mu (the bound of `1^T β`).
    mu: Vec<f64>,
}

impl PolyhedralLcp {
    /// Assembles the LCP of `problem` with `facets` directions per frictional contact.
    pub fn new(problem: &ContactProblem<'_>, facets: usize) -> Result<Self> {
        let dim = problem.dim;
        check_facets(dim, facets)?;
        check_size(problem, facets)?;
        let directions: Vec<[f64; 2]> = if dim == 2 {
            vec![[1.0, 0.0], [-1.0, 0.0]]
        } else {
            // the first half, with the axis directions exact (a rounding residue such as
            // cos(π/2) = 6e-17 would make a row of tiny data that Lemke's unit-free error
            // measure judges against itself), then their exact negatives
            let half: Vec<[f64; 2]> = (0..facets / 2)
                .map(|k| {
                    let a = std::f64::consts::TAU * k as f64 / facets as f64;
                    let snap = |v: f64| if v.abs() < 1e-15 { 0.0 } else { v };
                    [snap(a.cos()), snap(a.sin())]
                })
                .collect();
            half.iter()
                .copied()
                .chain(half.iter().map(|d| [-d[0], -d[1]]))
                .collect()
        };
        let nc = problem.nc;
        // per contact, the columns of B (contact space -> [r_n, β]): (index in z, the column's
        // dim components on the contact), so that A_top = B^T W B tile by tile
        let mut local: Vec<Vec<(usize, [f64; 3])>> =
            (0..nc).map(|i| vec![(i, [1.0, 0.0, 0.0])]).collect();
        let mut beta = vec![None; nc];
        let mut lambda = vec![None; nc];
        let mut p = nc;
        for (i, b) in beta.iter_mut().enumerate() {
            if problem.mu[i] > 0.0 {
                *b = Some(p);
                let e = axis_scale(problem, i);
                for d in &directions {
                    local[i].push((p, [0.0, e[0] * d[0], e[1] * d[1]]));
                    p += 1;
                }
            }
        }
        let mut nl = p;
        for l in lambda.iter_mut().zip(&beta) {
            if l.1.is_some() {
                *l.0 = Some(nl);
                nl += 1;
            }
        }
        let n = nl;
        let mut m = vec![0.0; n * n];
        let mut q = vec![0.0; n];
        let mut wv: Vec<[f64; 3]> = Vec::new();
        problem.for_each_block(|i, j, wij| {
            // W_ij v for every column v of contact j, then dotted with contact i's columns
            wv.clear();
            for (_, v) in &local[j] {
                let mut o = [0.0; 3];
                for (a, oa) in o.iter_mut().enumerate().take(dim) {
                    *oa = (0..dim).map(|c| wij[a][c] * v[c]).sum();
                }
                wv.push(o);
            }
            for (za, va) in &local[i] {
                let row = &mut m[za * n..(za + 1) * n];
                for ((zb, _), x) in local[j].iter().zip(&wv) {
                    row[*zb] += (0..dim).map(|a| va[a] * x[a]).sum::<f64>();
                }
            }
        });
        for (i, cols) in local.iter().enumerate() {
            let qi = &problem.q[i * dim..(i + 1) * dim];
            for (za, va) in cols {
                q[*za] = (0..dim).map(|a| va[a] * qi[a]).sum();
            }
        }
        let s = directions.len();
        // c_i = 1 / rho_i, in W's units (see the module notes)
        let scales = super::measures::ImpulseScale::of(problem, 1.0);
        let unit: Vec<f64> = (0..nc).map(|i| 1.0 / scales.rho(problem, i)).collect();
        for i in 0..nc {
            if let (Some(b0), Some(l)) = (beta[i], lambda[i]) {
                let c = unit[i];
                m[l * n + i] = problem.mu[i] * c;
                for k in b0..b0 + s {
                    m[k * n + l] = c;
                    m[l * n + k] = -c;
                }
            }
        }
        Ok(Self {
            n,
            m,
            q,
            dim,
            directions,
            scale: (0..nc).map(|i| axis_scale(problem, i)).collect(),
            beta,
            lambda,
            unit,
            mu: problem.mu.to_vec(),
        })
    }

    /// the index of contact i's normal impulse in z.
    pub fn normal_index(&self, i: usize) -> usize {
        i
    }

    /// the indices of contact i's β in z (empty when frictionless).
    pub fn beta_range(&self, i: usize) -> std::ops::Range<usize> {
        match self.beta[i] {
            Some(b) => b..b + self.directions.len(),
            None => 0..0,
        }
    }

    /// the index of contact i's λ in z (`None` when frictionless); z holds `λ / c_i` there
    /// (see the module notes and [`Self::slip_speed`]).
    pub fn lambda_index(&self, i: usize) -> Option<usize> {
        self.lambda[i]
    }

    /// contact i's λ of an LCP answer z, the sliding speed `c_i z_λ` (`None` when
    /// frictionless).
    pub fn slip_speed(&self, i: usize, z: &[f64]) -> Option<f64> {
        self.lambda[i].map(|l| self.unit[i] * z[l])
    }

    /// the unit tangent directions `d_k` (`(±1, 0)` in 2D), before the per-contact scale of
    /// [`Self::direction_scale`].
    pub fn directions(&self) -> &[[f64; 2]] {
        &self.directions
    }

    /// contact i's scale of the directions along its two tangents: `(1, 1)`, or
    /// `(mu_1 / m, mu_2 / m)` with anisotropic friction.
    pub fn direction_scale(&self, i: usize) -> [f64; 2] {
        self.scale[i]
    }

    /// the contact impulses `r_i = (r_n, D_i β_i)` (`dim nc` entries) of an LCP answer z.
    ///
    /// The answer is taken into the polygon exactly: Lemke's z meets `z >= 0` and
    /// `1^T β <= mu r_n` only to rounding (a β of 1e-14 beside `r_n = 0`: friction with no
    /// normal impulse), so negative entries count as 0 and β is scaled down to `mu r_n` where
    /// it exceeds it, a change at the LCP's rounding level.
    pub fn impulses(&self, z: &[f64]) -> Vec<f64> {
        let dim = self.dim;
        let nc = self.beta.len();
        let mut r = vec![0.0; dim * nc];
        for i in 0..nc {
            let rn = z[i].max(0.0);
            r[i * dim] = rn;
            let sum: f64 = self.beta_range(i).map(|k| z[k].max(0.0)).sum();
            let bound = self.mu[i] * rn;
            let shrink = if sum > bound { bound / sum } else { 1.0 };
            for (k, zk) in self.beta_range(i).enumerate() {
                let d = self.directions[k];
                let e = self.scale[i];
                let b = z[zk].max(0.0) * shrink;
                for t in 0..dim - 1 {
                    r[i * dim + 1 + t] += e[t] * d[t] * b;
                }
            }
        }
        r
    }
}

/// the scale of contact i's tangent directions: `(1, 1)` for the disk, `(mu_1 / m, mu_2 / m)`
/// with `m = max(mu_1, mu_2) = mu_i` for the ellipse.
fn axis_scale(problem: &ContactProblem<'_>, i: usize) -> [f64; 2] {
    match problem.anisotropy(i) {
        Some(p) => {
            let m = p[0].max(p[1]);
            [p[0] / m, p[1] / m]
        }
        None => [1.0, 1.0],
    }
}

/// refuses, before any allocation, a dense LCP (`n = nc + (facets + 1) n_f` unknowns for `n_f`
/// frictional contacts) whose matrix and Lemke workspace exceed the memory budget.
fn check_size(problem: &ContactProblem<'_>, facets: usize) -> Result<()> {
    let nf = problem.mu.iter().filter(|&&m| m > 0.0).count();
    let n = facets
        .checked_add(1)
        .and_then(|f| f.checked_mul(nf))
        .and_then(|x| x.checked_add(problem.nc));
    let entries = n
        .and_then(crate::limits::dense_lemke_entries)
        .unwrap_or(usize::MAX);
    crate::limits::check_bytes(
        format_args!(
            "the dense polyhedral LCP of {} contacts ({nf} with friction) with {facets} facets \
             ({} unknowns)",
            problem.nc,
            n.map_or_else(|| "too many".to_string(), |n| n.to_string())
        ),
        entries,
        8,
        "use fewer facets, or method 'nsgs' or 'prox', whose memory grows with W's nonzeros",
    )
    .map(|_| ())
}

fn check_facets(dim: usize, facets: usize) -> Result<()> {
    if dim == 2 && facets != 2 {
        return Err(CoulombError::InvalidParameter(format!(
            "facets must be 2 in 2D (the tangent directions +1 and -1, which are exact), got \
             {facets}"
        )));
    }
    if dim == 3 && (facets < 4 || !facets.is_multiple_of(2)) {
        return Err(CoulombError::InvalidParameter(format!(
            "facets must be even and at least 4 in 3D (tangent directions in +/- pairs), got \
             {facets}"
        )));
    }
    Ok(())
}

/// fixed covering vectors tried after the other engine's path (see [`other_paths`]): on the
/// LCPs of contacts with mu of 1e8 and more, whether a path solves depends on the rounding of
/// the data (a one-ulp change of W or q changes it as often as a change of units does), so
/// each path is a draw; six make it rarer that all fail in one rounding and not in another
/// (on the property campaign two left 23 unit-dependent statuses in 2419 such problems, six
/// leave 18). They run only when the paths before them failed.
const COVERING_PATHS: usize = 6;

/// Other Lemke paths on the same polyhedral LCP, tried in turn when the first does not solve
/// it (only under the default engine and covering vector, which they replace): the other
/// engine (the product form and the tableau round differently, and with mu of 1e4 and more
/// the LCP is conditioned like mu, so a lexicographic tie or a pivot near the tolerance can
/// go either way), then [`COVERING_PATHS`] fixed covering vectors spread in [0.5, 1.5) on the problem in
/// normalized units. Each path is deterministic, and every answer is judged by the same rule.
fn other_paths(s: &LemkeSettings, n: usize) -> Vec<LemkeSettings> {
    if s.engine != LemkeEngine::Auto || s.covering_vector.is_some() || n == 0 {
        return Vec::new();
    }
    let other = if (16..=1024).contains(&n) {
        LemkeEngine::Tableau
    } else {
        LemkeEngine::ProductForm
    };
    let mut out = vec![LemkeSettings {
        engine: other,
        ..s.clone()
    }];
    for k in (1..=COVERING_PATHS).map(|k| k as f64) {
        // the golden-ratio sequence: reproducible and never zero
        let phi = 0.618_033_988_749_895 * k;
        let d: Vec<f64> = (0..n)
            .map(|i| 0.5 + ((i as f64 + 1.0) * phi).fract())
            .collect();
        out.push(LemkeSettings {
            covering_vector: Some(d),
            ..s.clone()
        });
    }
    out
}

/// The LCP's answer when every contact's free normal velocity is `q_n >= 0`: then `r = 0`
/// solves the contact problem exactly (Signorini's condition holds with `u = q`, and De
/// Saxce's `u + mu ||u_t|| n` lies in the dual cone exactly when `u_n >= 0`), and the
/// polyhedral LCP too, with `z = (0, 0, λ)`, each contact's `z_λ = max(0, max_k -b_k) / c_i`
/// over its β rows `b_k = d_k . q_t` (the least sliding speed for which every
/// `w_β = b + c_i z_λ 1` is `>= 0`; `w_λ = 0`). Only the signs of `q_n` decide, so the answer
/// does not depend on the units; Lemke's path is not needed for it, and on such an LCP (its
/// λ rows start degenerate, `b = 0`) it could end on a ray in some roundings of the data
/// (a one-contact problem with mu = 0.5 solved in 5 pivots with W and q as given and ended
/// on a ray with both times 1.5). `None` when some `q_n < 0` or the answer misses `tol` on
/// the LCP.
fn separating_answer(
    problem: &ContactProblem<'_>,
    lcp: &PolyhedralLcp,
    lref: &LcpRef<'_>,
    tol: f64,
) -> Result<Option<LcpSolution>> {
    // q is finite (checked when the problem was made)
    if (0..problem.nc).any(|i| problem.q[i * problem.dim] < 0.0) {
        return Ok(None);
    }
    let mut z = vec![0.0; lcp.n];
    let mut basis = Vec::new();
    for i in 0..problem.nc {
        if let Some(l) = lcp.lambda[i] {
            let need = lcp.beta_range(i).map(|k| -lcp.q[k]).fold(0.0f64, f64::max);
            if need > 0.0 {
                z[l] = need / lcp.unit[i];
                basis.push(l);
            }
        }
    }
    let (w, measures) = measure_lcp(lref, &z)?;
    if !crate::lcp::passes(&measures, tol) {
        return Ok(None);
    }
    Ok(Some(LcpSolution {
        z,
        w,
        status: LcpStatus::Solved,
        message: "solved without pivots: every contact has q_n >= 0, so r = 0".into(),
        measures,
        pivots: 0,
        iterations: 0,
        basis,
        warm_start: WarmStart::None,
        pivots_saved: 0,
        polished: false,
        restarts: 0,
        solutions: Vec::new(),
    }))
}

/// Solves the friction-contact problem on the polyhedral cone by Lemke's method (see the
/// module notes), returning the impulses together with the LCP answer itself.
pub fn solve_polyhedral_lcp(
    problem: &ContactProblem<'_>,
    settings: &PolyhedralSettings,
) -> Result<(ContactSolution, PolyhedralLcp, LcpSolution)> {
    let lcp = PolyhedralLcp::new(problem, settings.facets)?;
    let lref = LcpRef::new(lcp.n, &lcp.m, &lcp.q)?;
    let mut u = vec![0.0; problem.size()];
    let tol = settings.lemke.tol;
    let accepted = |ls: &LcpSolution, r: &[f64], u: &mut [f64]| {
        ls.status == LcpStatus::Solved
            && (problem.dim != 2 || measure_into(problem, r, u).passes(tol))
    };
    // how an answer of the large-mu LCPs was found, or that they did not find one
    let (mut note, mut refused) = (String::new(), String::new());
    // the settings are checked before the shortcut as Lemke would check them
    crate::lcp::lemke::validate(&lref, &settings.lemke)?;
    let mut ls = match separating_answer(problem, &lcp, &lref, tol)? {
        Some(ls) => ls,
        None => solve_lemke(&lref, &settings.lemke)?,
    };
    let mut r = lcp.impulses(&ls.z);
    let mut pivots = ls.pivots;
    if !accepted(&ls, &r, &mut u) {
        // other paths (see `other_paths`); the first that solves is kept, else the first's
        // verdict stands
        for alt in other_paths(&settings.lemke, lcp.n) {
            let t = solve_lemke(&lref, &alt)?;
            pivots += t.pivots;
            let rt = lcp.impulses(&t.z);
            if accepted(&t, &rt, &mut u) {
                ls = t;
                r = rt;
                break;
            }
        }
        if !accepted(&ls, &r, &mut u) {
            // large mu: the capped and scaled LCPs, answers checked on this one
            let found = large_mu::solve(problem, &lcp, &lref, &settings.lemke, |t, rt| {
                accepted(t, rt, &mut u)
            })?;
            pivots += found.pivots;
            if let Some((t, rt)) = found.answer {
                note = format!(", {}", t.message);
                ls = t;
                r = rt;
            } else if found.pivots > 0 {
                refused = format!(
                    "; the LCPs with the cone rows of mu > {:e} capped, or sliding contacts \
                     in units of r_n, gave no answer of this one either ({} pivots)",
                    large_mu::CAPS[0],
                    found.pivots
                );
            }
        }
        ls.pivots = pivots;
    }
    let measures = measure_into(problem, &r, &mut u);
    let lm = &ls.measures;
    let what = format!(
        "polyhedral LCP ({} facets, {} unknowns)",
        lcp.directions.len(),
        lcp.n
    );
    let verdict = LemkeVerdict::of(problem.dim, ls.status, &measures, settings.lemke.tol);
    let status = verdict.status();
    let message = match verdict {
        LemkeVerdict::MissesTheInterval => format!(
            "{what} solved by Lemke in {} pivots (LCP error {}), but the impulses miss \
             the tolerance on the contact problem ({}){refused}",
            ls.pivots,
            Readable(lm.error),
            measures.shortfall(settings.lemke.tol)
        ),
        LemkeVerdict::Solved => format!(
            "{what} solved by Lemke in {} pivots{note} (LCP error {}; against the exact \
             disk scaled_error {})",
            ls.pivots,
            Readable(lm.error),
            Readable(measures.scaled_error)
        ),
        LemkeVerdict::PassesTheRule => format!(
            "{what}: Lemke {} ({}), but its impulses pass the tolerance on the contact \
             problem (scaled_error {}, error_q {})",
            ls.status,
            ls.message,
            Readable(measures.scaled_error),
            Readable(measures.error_q)
        ),
        LemkeVerdict::PivotLimit | LemkeVerdict::Failed => {
            format!("{what}: Lemke {}: {}{refused}", ls.status, ls.message)
        }
    };
    let sol = ContactSolution {
        impulse: r,
        velocity: u,
        status,
        message,
        iterations: ls.pivots,
        measures,
    };
    Ok((sol, lcp, ls))
}

/// Solves the friction-contact problem on the polyhedral cone by Lemke's method (see the
/// module notes). `iterations` counts Lemke's pivots; success means the LCP was solved.
pub fn solve_polyhedral(
    problem: &ContactProblem<'_>,
    settings: &PolyhedralSettings,
) -> Result<ContactSolution> {
    solve_polyhedral_lcp(problem, settings).map(|(s, _, _)| s)
}

#[path = "polyhedral_large_mu.rs"]
mod large_mu;
#[path = "polyhedral_verdict.rs"]
mod verdict;
pub(crate) use verdict::LemkeVerdict;

#[cfg(test)]
#[path = "polyhedral_tests.rs"]
mod tests;
