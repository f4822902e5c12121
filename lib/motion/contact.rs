//! Contacts as runs of frames: the one rule both foot lockers (`edit::foot_lock` on clips,
//! `repr::anytop::lock` inside the sampler) pin a foot by, so the two cannot drift apart on
//! what a contact is or where it holds.

use glam::DVec3;

/// One contact: frames `first..=last`, held at `pin`, the foot's mean position over them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    pub first: usize,
    pub last: usize,
    pub pin: DVec3,
}

/// Each maximal run of frames in `0..frames` where `down(t)`, with the mean of `at(t)` over it.
/// Why the mean: it moves the foot least over the whole contact (a least-squares pin), so a
/// foot that slid a little is held in the middle of its slide, not at either end.
pub fn contacts(frames: usize, down: impl Fn(usize) -> bool, at: impl Fn(usize) -> DVec3) -> Vec<Contact> {
    let mut out = Vec::new();
    let mut first = None;
    for t in 0..=frames {
        match (t < frames && down(t), first) {
            (true, None) => first = Some(t),
            (false, Some(s)) => {
                let pin = (s..t).map(&at).sum::<DVec3>() / (t - s) as f64;
                out.push(Contact { first: s, last: t - 1, pin });
                first = None;
            }
            _ => {}
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_are_maximal_and_pinned_at_their_mean() {
        let down = [false, true, true, false, true, true, true];
        let at = |t: usize| DVec3::new(t as f64, 0.0, 2.0 * t as f64);
        let got = contacts(down.len(), |t| down[t], at);
        assert_eq!(got, vec![Contact { first: 1, last: 2, pin: DVec3::new(1.5, 0.0, 3.0) }, Contact { first: 4, last: 6, pin: DVec3::new(5.0, 0.0, 10.0) },]);
        assert!(contacts(0, |_| true, at).is_empty());
        assert!(contacts(3, |_| false, at).is_empty());
        let all = contacts(3, |_| true, at);
        assert_eq!((all.len(), all[0].first, all[0].last), (1, 0, 2));
    }
}
