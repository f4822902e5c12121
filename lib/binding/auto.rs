//! Automatic bone binding (`mo-retarget --bind auto`, `mo-dift --joints --as-binding`): the
//! one-to-one joint correspondence of `correspond` (names, sides, limb pairs, topology, rest
//! pose), narrowed to the pairs worth binding.
//!
//! Motion2Motion's appendix A binds the few most similar bone chains (a 6.1% binding rate).
//! Our binder binds every confident pair instead (`correspond::bindable`: both joints move a
//! bone, same side, same limb pair, neither joint has a better partner, no toes, the same place
//! along both limbs with bones pointing the same way; and each matched limb tied at its first
//! joint and its end: foot, hand, tip, or a bird's and a mammal's ankles): a binding that ties
//! each leg to its leg and the spine to the spine is what a person writes by hand, and on
//! real rigs the few-pairs binding left limbs to chance (issue 24). `rate` stays as a limit
//! for those who want the paper's setting. When fewer than `min_pairs` pairs are confident,
//! the best other compatible pairs make up the number.

use super::{Binding, Pair, FORMAT};
pub use crate::correspond::Body;
use crate::correspond::{self, CorrespondError, Evidence};
use crate::skeleton::Skeleton;

/// How the automatic binder chooses.
#[derive(Clone, Debug)]
pub struct AutoOptions {
    /// At most this binding rate 2|M| / (J_source + J_target) (Motion2Motion's appendix B:
    /// 6.1%); `None`: every confident pair.
    pub rate: Option<f64>,
    /// Never fewer pairs than this (when there are enough candidates).
    pub min_pairs: usize,
    /// Which evidence the correspondence uses.
    pub evidence: Evidence,
}

impl Default for AutoOptions {
    fn default() -> Self {
        AutoOptions { rate: None, min_pairs: 4, evidence: Evidence::ALL }
    }
}

/// A chosen pair with its score (higher is surer).
#[derive(Clone, Debug, PartialEq)]
pub struct Choice {
    pub source: usize,
    pub target: usize,
    pub score: f64,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AutoError {
    #[error(transparent)]
    Correspond(#[from] CorrespondError),
    #[error("{which} skeleton has no joint with children below the root, so there is no bone to bind")]
    NoCandidates { which: &'static str },
    #[error("binding rate must be within (0, 1], found {0}")]
    Rate(f64),
}

/// How many pairs `rate` asks for on skeletons of `js` and `jt` joints.
pub fn pair_count(rate: f64, js: usize, jt: usize, min_pairs: usize) -> usize {
    ((rate * (js + jt) as f64 / 2.0).round() as usize).max(min_pairs).max(1)
}

/// Bind `source` to `target`: pairs in order of decreasing score.
pub fn auto_bind(source: &Body, target: &Body, opts: &AutoOptions) -> Result<Vec<Choice>, AutoError> {
    let scores = correspond::scores(source, target, opts.evidence, None)?;
    choose(&scores, source.skeleton, target.skeleton, opts)
}

/// The binding from scores already computed (`mo-dift` adds DIFT evidence to them first).
pub fn choose(scores: &correspond::Scores, source: &Skeleton, target: &Skeleton, opts: &AutoOptions) -> Result<Vec<Choice>, AutoError> {
    if let Some(rate) = opts.rate {
        if !(rate.is_finite() && rate > 0.0 && rate <= 1.0) {
            return Err(AutoError::Rate(rate));
        }
    }
    for (which, s) in [("source", source), ("target", target)] {
        let children = s.children();
        if !(1..s.len()).any(|j| !children[j].is_empty()) {
            return Err(AutoError::NoCandidates { which });
        }
    }
    let pairs = correspond::assign(scores);
    let mut chosen = correspond::bindable(scores, &pairs);
    if chosen.len() < opts.min_pairs {
        // Too few confident pairs: the best compatible ones, confident or not.
        let mut more: Vec<correspond::Pair> = correspond::compatible(scores, &pairs).into_iter().filter(|p| !chosen.contains(p)).collect();
        more.truncate(opts.min_pairs - chosen.len());
        chosen.extend(more);
    }
    if let Some(rate) = opts.rate {
        chosen.truncate(pair_count(rate, source.len(), target.len(), opts.min_pairs));
    }
    Ok(chosen.into_iter().map(|p| Choice { source: p.source, target: p.target, score: p.score }).collect())
}

/// The choices as a binding file (names as the skeletons spell them, scores kept).
pub fn to_binding(choices: &[Choice], source: &Skeleton, source_name: &str, target: &Skeleton, target_name: &str) -> Binding {
    Binding {
        format: Some(FORMAT.to_string()),
        source_name: Some(source_name.to_string()),
        target_name: Some(target_name.to_string()),
        mapping: choices
            .iter()
            .map(|c| Pair {
                source: source.joints[c.source].name.clone(),
                target: target.joints[c.target].name.clone(),
                score: Some((c.score * 1000.0).round() / 1000.0),
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::correspond::tests::body_of;

    #[test]
    fn a_skeleton_binds_to_itself_joint_for_joint() {
        for name in ["biped", "quadruped", "spider", "dragon"] {
            let (s, rest) = body_of(name);
            let body = Body { skeleton: &s, rest: &rest };
            let opts = AutoOptions::default();
            let pairs = auto_bind(&body, &body, &opts).unwrap();
            assert!(pairs.len() >= 4, "{name}: {} pairs", pairs.len());
            for c in &pairs {
                assert_eq!(c.source, c.target, "{name}: {} bound to {}", s.joints[c.source].name, s.joints[c.target].name);
            }
        }
    }

    #[test]
    fn geometry_alone_binds_a_renamed_copy_and_never_swaps_sides() {
        let (s, rest) = body_of("biped");
        let mut renamed = s.clone();
        for (i, j) in renamed.joints.iter_mut().enumerate() {
            // Numbers carry no side and no word: only geometry is left to bind by.
            j.name = format!("j{i}");
        }
        let opts = AutoOptions { evidence: Evidence::GEOMETRY, ..AutoOptions::default() };
        let pairs = auto_bind(&Body { skeleton: &s, rest: &rest }, &Body { skeleton: &renamed, rest: &rest }, &opts).unwrap();
        let correct = pairs.iter().filter(|c| c.source == c.target).count();
        assert!(correct * 10 >= pairs.len() * 9, "{correct} of {} correct", pairs.len());
    }

    #[test]
    fn rate_controls_the_count_and_bad_input_is_an_error() {
        assert_eq!(pair_count(0.061, 41, 86, 4), 4);
        assert_eq!(pair_count(0.2, 41, 86, 4), 13);
        let (s, rest) = body_of("quadruped");
        let body = Body { skeleton: &s, rest: &rest };
        let few = auto_bind(&body, &body, &AutoOptions { rate: Some(0.061), ..AutoOptions::default() }).unwrap();
        let all = auto_bind(&body, &body, &AutoOptions::default()).unwrap();
        // Unlimited: every joint that moves a bone (a leaf with an End Site too) binds to
        // itself, but toes (feet below the top of their foot).
        let children = s.children();
        let feet = crate::skeleton::roles::feet(&s).0;
        let toe = |j: usize| feet.contains(&j) && s.joints[j].parent.is_some_and(|p| feet.contains(&p));
        let moves = |j: usize| !children[j].is_empty() || !s.joints[j].end_sites.is_empty();
        assert_eq!(all.len(), (1..s.len()).filter(|&j| moves(j) && !toe(j)).count());
        assert_eq!(few.len(), pair_count(0.061, s.len(), s.len(), 4));
        assert_eq!(auto_bind(&body, &body, &AutoOptions { rate: Some(0.0), ..AutoOptions::default() }).unwrap_err(), AutoError::Rate(0.0));
        let short = Body { skeleton: &s, rest: &rest[..2] };
        assert!(matches!(auto_bind(&short, &body, &AutoOptions::default()), Err(AutoError::Correspond(CorrespondError::RestSize { .. }))));
        let binding = to_binding(&few, &s, "a", &s, "b");
        let text = binding.to_json();
        let back = Binding::from_json(&text, "auto.json").unwrap();
        assert_eq!(back.resolve("auto.json", &s, "a", &s, "b").unwrap(), few.iter().map(|c| (c.source, c.target)).collect::<Vec<_>>());
    }
}
