//! Where the steps go: the state kind that limits each error test and what the contacts did in
//! each rejected attempt (development diagnostics, off by default).

use crate::physics::contact::TrackState;

/// Where the steps go (development diagnostics, printed by `examples/step_profile`; not part
/// of a run's results), settle included. The limiting kinds are counted for the implicit
/// methods; rejections for every method.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct StepDiagnostics {
    /// Attempts that reached the error test, by step-size decade (`[k]` holds
    /// `1e-(k+1) <= h < 1e-k` s, the last entry everything shorter) and by the kind of state
    /// entry with the largest weighted error: 0 position, 1 rotation (quaternion),
    /// 2 velocity, 3 angular velocity.
    pub limiting_kind: [[u64; 4]; STEP_DECADES],
    /// Rejected attempts, `[0]` Newton failures and `[1]` error-test failures, by what the
    /// contacts did between the step start and the attempt's last evaluation: 0 a contact
    /// patch appeared (onset), 1 one vanished (separation), 2 a patch's IMPACT force switched
    /// between clamped at zero and positive, 3 none of these (same contact set).
    pub rejections_by_event: [[u64; 4]; 2],
}

/// Step-size decades in [`StepDiagnostics::limiting_kind`].
pub const STEP_DECADES: usize = 12;

/// Contact set of a track list: (contact, track, force > 0), sorted.
pub(super) fn contact_set_into(tracks: &[TrackState], out: &mut Vec<(u32, u32, bool)>) {
    out.clear();
    out.extend(
        tracks
            .iter()
            .map(|t| (t.contact, t.track, t.normal_force > 0.0)),
    );
    out.sort_unstable_by_key(|&(c, k, _)| (c, k));
}

/// What changed from contact set `a` to `b`: 0 onset, 1 separation, 2 clamp switch, 3 nothing.
pub(super) fn contact_change(a: &[(u32, u32, bool)], b: &[(u32, u32, bool)]) -> usize {
    let find = |set: &[(u32, u32, bool)], x: &(u32, u32, bool)| {
        set.binary_search_by_key(&(x.0, x.1), |&(c, k, _)| (c, k))
            .ok()
    };
    if b.iter().any(|x| find(a, x).is_none()) {
        0
    } else if a.iter().any(|x| find(b, x).is_none()) {
        1
    } else if a.iter().any(|x| find(b, x).is_some_and(|i| b[i].2 != x.2)) {
        2
    } else {
        3
    }
}

#[cfg(test)]
mod tests {
    use super::contact_change;

    #[test]
    fn contact_changes_are_classified_onset_first() {
        let a = [(0, 1, true), (2, 0, false)];
        assert_eq!(contact_change(&a, &a), 3);
        assert_eq!(
            contact_change(&a, &[(0, 1, true), (1, 0, true), (2, 0, false)]),
            0
        );
        assert_eq!(contact_change(&a, &[(0, 1, true)]), 1);
        assert_eq!(contact_change(&a, &[(0, 1, true), (2, 0, true)]), 2);
        // A patch replaced by another is an onset (the new one) before a separation.
        assert_eq!(contact_change(&a, &[(0, 1, true), (3, 0, true)]), 0);
        assert_eq!(contact_change(&[], &[]), 3);
    }
}
