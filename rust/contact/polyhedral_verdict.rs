//! Lemke's verdict on a friction-contact problem (module `polyhedral`).

use crate::contact::ContactStatus;
use crate::lcp::LcpStatus;

/// Lemke's verdict on a friction-contact problem, shared by [`super::solve_polyhedral`] and the
/// stepper's Lemke: from Lemke's status on the polyhedral LCP and the impulses' measures on
/// the contact problem (`measures`, the exact disk), against `tol`.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum LemkeVerdict {
    /// 2D: the polygon is the interval, so the LCP is the problem and the success rule of
    /// every contact method applies to the impulses; Lemke solved the LCP but they miss it.
    MissesTheInterval,
    /// Lemke solved the LCP (in 3D the polygon's answer, whatever it misses of the disk).
    Solved,
    /// Lemke's own certificate (a residual test on the LCP, in its scaling) failed, but the
    /// impulses pass the exact rule on the original problem.
    PassesTheRule,
    /// Lemke stopped at its pivot limit and the impulses miss the rule.
    PivotLimit,
    /// Lemke failed otherwise (a numerical failure) and the impulses miss the rule.
    Failed,
}

impl LemkeVerdict {
    /// the verdict of Lemke's `status` with impulses measuring `measures` in `dim`.
    pub(crate) fn of(
        dim: usize,
        status: LcpStatus,
        measures: &crate::contact::ContactMeasures,
        tol: f64,
    ) -> Self {
        let passes = measures.passes(tol);
        match status {
            LcpStatus::Solved if dim == 2 && !passes => Self::MissesTheInterval,
            LcpStatus::Solved => Self::Solved,
            _ if passes => Self::PassesTheRule,
            LcpStatus::PivotLimit => Self::PivotLimit,
            _ => Self::Failed,
        }
    }

    /// the contact status of the verdict.
    pub(crate) fn status(self) -> ContactStatus {
        match self {
            Self::Solved | Self::PassesTheRule => ContactStatus::Solved,
            Self::PivotLimit => ContactStatus::IterationLimit,
            Self::MissesTheInterval | Self::Failed => ContactStatus::NumericalFailure,
        }
    }
}
