//! Contact persistence and impact memory: what one contact carries from the step in which an
//! impact stops its approach to the step that gives the rebound back.
//!
//! An open contact that would close within a step gets the gap term
//! `0 <= P_n ⊥ J_n v_{k+1} + g / h >= 0`: the contact may close during the step but not pass
//! through. When that step pushes (`P_n > 0`) and its gap term holds with equality (the
//! contact closed, to the gap tolerance: a rounding-sized impulse on a contact still closing
//! from afar is no landing) an impact has happened inside it, inelastically;
//! its approach velocity `v_n^- = J_n(q_k) v_k` is recorded here, keyed to the contact's
//! persistent identity, and the next step applies the impact law with it (Newton's
//! `0 <= P_n ⊥ J_n v_{k+2} + e v_n^- >= 0`, or Poisson's restitution of the compression
//! impulse carried over), so the rebound is `-e v_n^-` wherever in the step the impact fell.
//!
//! The rebound is keyed to this record, not to the size of the gap left after the landing
//! step: the gap term is linear in v, so for a rotating body or a turning normal the true gap
//! left is O(h^2) (a rod end, a box corner, two spheres whose normal turns), and a rule keyed
//! on "closed, `g <= gap_tolerance`" would drop the rebound (Moreau's and Jean's schemes
//! likewise key restitution to the contact, not to a position threshold).
//!
//! A record belongs to one contact and one impact: it is consumed by the step after the
//! landing (whatever that step's impulse), it expires when the contact is no longer active,
//! and it is never replayed later (a contact hovering open for some steps and then closing
//! again gets no stale rebound).

/// The impact record of one contact (see the module docs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct ImpactMemory {
    /// whether the last step stopped this contact's approach with the gap term (`P_n > 0`,
    /// the term tight):
    /// the next step owes it the rebound.
    pub pending: bool,
    /// the approach velocity `v_n^- = J_n(q_k) v_k` of that step (m/s, `<= 0`).
    pub approach: f64,
    /// the normal impulse of that step (N s): the compression already applied, which
    /// Poisson's law restitutes.
    pub compression: f64,
}

impl ImpactMemory {
    /// the record of a landing step: the gap term pushed `p_n` against the approach `vn_k`.
    pub fn landed(vn_k: f64, p_n: f64) -> Self {
        Self {
            pending: true,
            approach: vn_k.min(0.0),
            compression: p_n,
        }
    }

    /// the approach velocity the impact law of this step uses for a contact whose current
    /// normal velocity is `vn_k`: the more negative of the two, or 0 for a separating contact.
    pub fn approach_with(&self, vn_k: f64) -> f64 {
        let remembered = if self.pending { self.approach } else { 0.0 };
        vn_k.min(remembered).min(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_gives_its_approach_once_and_only_while_pending() {
        let m = ImpactMemory::landed(-3.0, 0.5);
        assert_eq!(m.approach_with(-1e-9), -3.0);
        assert_eq!(m.approach_with(-4.0), -4.0);
        let consumed = ImpactMemory::default();
        assert_eq!(consumed.approach_with(0.2), 0.0);
        assert_eq!(consumed.approach_with(-0.2), -0.2);
        // a separating landing records no approach
        assert_eq!(ImpactMemory::landed(0.1, 0.5).approach, 0.0);
    }
}
