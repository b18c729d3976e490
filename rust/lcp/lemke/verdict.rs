//! The status and message of one Lemke path's answer.

use std::fmt::Write;

use super::super::{passes, LcpSolution, LcpStatus};
use super::Ending;
use crate::readable::{push_count, Readable};

/// The status and message of a path's answer (already in `out`); `true` when it is final,
/// `false` after a ray, which a restart with another covering vector may still overcome.
/// The message is written into `out.message`'s own buffer (a kept solution reuses it).
pub(super) fn verdict(
    out: &mut LcpSolution,
    ending: Ending,
    polished: bool,
    tol: f64,
    max_pivots: usize,
    attempt: usize,
) -> bool {
    let m = out.measures;
    match ending {
        Ending::Ray | Ending::Limit | Ending::Cycle if passes(&m, tol) => {
            out.status = LcpStatus::Solved;
            out.message.clear();
            let _ = write!(
                out.message,
                "solved in {} pivots (error {}{}; the path ended on {}, but the answer \
                 there passes tol)",
                out.pivots,
                Readable(m.error),
                if polished { ", polished" } else { "" },
                match ending {
                    Ending::Ray => "a ray",
                    Ending::Cycle => "a cycle",
                    _ => "the pivot limit",
                }
            );
            return true;
        }
        Ending::Terminal if passes(&m, tol) => {
            out.status = LcpStatus::Solved;
            // "solved in {pivots} pivots (error {error}[, polished])", pushed piece by piece:
            // every solve of a batch or a simulation writes it
            let text = &mut out.message;
            text.clear();
            text.push_str("solved in ");
            push_count(text, out.pivots);
            text.push_str(" pivots (error ");
            Readable(m.error).push_to(text);
            text.push_str(if polished { ", polished)" } else { ")" });
            return true;
        }
        // a rounding casualty of degenerate pivots (a wrong leaving row on a singular W,
        // for example): another covering vector takes another path, so not final
        Ending::Terminal => {
            out.status = LcpStatus::NumericalFailure;
            out.message.clear();
            let _ = write!(
                out.message,
                "z0 left the basis but the answer fails tol {}: error {}, \
                 scaled error {} (ill-conditioned basis; {} covering vector(s) tried)",
                Readable(tol),
                Readable(m.error),
                Readable(m.scaled_error),
                attempt + 1
            );
        }
        Ending::Cycle => {
            out.status = LcpStatus::NumericalFailure;
            out.message.clear();
            let _ = write!(
                out.message,
                "the path cycled (rounding at degenerate ties) after {} pivots, with {} \
                 covering vector(s) tried: error {}",
                out.pivots,
                attempt + 1,
                Readable(m.error)
            );
        }
        Ending::Ray => {
            out.status = LcpStatus::RayTermination;
            out.message.clear();
            let _ = write!(
                out.message,
                "ray termination after {} pivots with {} covering vector(s): no solution \
                 found on Lemke's path (for copositive-plus M, e.g. positive semidefinite, \
                 this proves there is none)",
                out.pivots,
                attempt + 1
            );
        }
        Ending::Limit => {
            out.status = LcpStatus::PivotLimit;
            out.message.clear();
            let _ = write!(
                out.message,
                "stopped at the pivot limit ({max_pivots}) with error {}",
                Readable(m.error)
            );
            return true;
        }
        Ending::NonFinite => {
            out.status = LcpStatus::NumericalFailure;
            out.message.clear();
            let _ = write!(
                out.message,
                "the tableau became non-finite after {} pivots",
                out.pivots
            );
            return true;
        }
    }
    false
}
