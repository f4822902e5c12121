//! What must hold before clips are compared: one skeleton, one length, a binding that binds
//! something. The reports (`metrics::report`) assume it; these checks say, in one sentence that
//! names the clips, why a comparison cannot be made, for the tool and library callers alike.

use super::report::ReportError;
use crate::document::AnyTopSection;
use crate::motion::Clip;
use crate::repr::anytop::{RigError, RigOptions};

/// A reference and a result for reconstruction metrics: one skeleton, one length. A result one
/// frame short of the reference (an encode -> decode round trip: features of an F-frame clip
/// describe F - 1 frames) is compared on its frames: the reference is cut, and the note that
/// says so is returned.
pub fn reconstruction_pair(reference: &mut Clip, result: &Clip) -> Result<Option<String>, ReportError> {
    let (a, b) = (reference, result);
    if a.skeleton.len() != b.skeleton.len() {
        return Err(ReportError::Invalid(format!(
            "{} has {} joints but {} has {}: reconstruction compares motions on one skeleton",
            a.name,
            a.skeleton.len(),
            b.name,
            b.skeleton.len()
        )));
    }
    let mut note = None;
    if b.motion.frames + 1 == a.motion.frames {
        note = Some(format!("{} has one frame fewer than {} (a decoded round trip); comparing its {} frames", b.name, a.name, b.motion.frames));
        a.motion = a.motion.first_frames(b.motion.frames);
    }
    if a.motion.frames != b.motion.frames {
        return Err(ReportError::Invalid(format!(
            "{} has {} frames but {} has {}: reconstruction compares frame by frame",
            a.name, a.motion.frames, b.name, b.motion.frames
        )));
    }
    Ok(note)
}

/// Transfer results all on the first one's skeleton (as many joints).
pub fn one_target(results: &[Clip]) -> Result<(), ReportError> {
    let Some((target, rest)) = results.split_first() else { return Ok(()) };
    match rest.iter().find(|r| r.skeleton.len() != target.skeleton.len()) {
        Some(r) => Err(ReportError::Invalid(format!(
            "{} has {} joints but {} has {}: all results must be on one skeleton",
            r.name,
            r.skeleton.len(),
            target.name,
            target.skeleton.len()
        ))),
        None => Ok(()),
    }
}

/// A binding for transfer metrics binds at least one pair.
pub fn some_pairs(source: &Clip, target: &Clip, pairs: &[(usize, usize)]) -> Result<(), ReportError> {
    if pairs.is_empty() {
        return Err(ReportError::Invalid(format!("{} and {} share no joint names: give --binding", source.name, target.name)));
    }
    Ok(())
}

/// Ground truth and generated clips of generation metrics on one skeleton (joint count and
/// parents), the first ground-truth clip's.
pub fn one_skeleton(gt: &[Clip], generated: &[Clip]) -> Result<(), ReportError> {
    let Some(first) = gt.first() else { return Ok(()) };
    for l in gt.iter().chain(generated) {
        if l.skeleton.len() != first.skeleton.len() || l.skeleton.joints.iter().zip(&first.skeleton.joints).any(|(a, b)| a.parent != b.parent) {
            return Err(ReportError::Invalid(format!(
                "{} and {} are not on the same skeleton: generation metrics compare clips of one skeleton",
                l.name, first.name
            )));
        }
    }
    Ok(())
}

/// The rig generation metrics put every clip on when no skeleton document gives one: built on
/// the first ground-truth clip as AnyTop would, so positions share AnyTop's scale.
pub fn generation_rig(first: &Clip) -> Result<AnyTopSection, ReportError> {
    AnyTopSection::new(&first.skeleton, &first.motion.first_frames(2), &RigOptions::default())
        .map_err(|source| ReportError::from(RigError { name: first.name.clone(), source }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clip(name: &str, frames: usize) -> Clip {
        let (skeleton, motion) = crate::synth::creature("quadruped", 0).unwrap();
        Clip { name: name.into(), motion: motion.first_frames(frames), skeleton }
    }

    #[test]
    fn a_round_trip_one_frame_short_is_compared_on_its_frames() {
        let (mut a, b) = (clip("a", 10), clip("b", 9));
        let note = reconstruction_pair(&mut a, &b).unwrap();
        assert!(note.is_some_and(|n| n.contains("one frame fewer")));
        assert_eq!(a.motion.frames, 9);
        let (mut a, b) = (clip("a", 10), clip("b", 7));
        assert!(reconstruction_pair(&mut a, &b).unwrap_err().to_string().contains("frame by frame"));
        assert!(one_skeleton(&[clip("a", 3)], &[clip("b", 4)]).is_ok());
        assert!(some_pairs(&clip("a", 2), &clip("b", 2), &[]).is_err());
    }
}
