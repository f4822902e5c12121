//! How far a skeleton lies from the skeletons a model was trained on: the out-of-distribution
//! (OOD) score every tool that runs a learned model prints a warning from.
//!
//! AnyTop (Table 2) scores this with a Wasserstein distance on graph features and shows quality
//! falling as it grows. Ours compares two skeletons on three things, each about 0 for the same
//! skeleton and about 1 for unrelated ones:
//! * graph: 1-D Wasserstein distances between the joints' depths, child counts and heights
//!   above their deepest leaf (the first and last relative to the larger mean), and the log
//!   ratio of joint counts;
//! * proportions: Wasserstein distances between bone lengths and rest distances from the root,
//!   both over the rest pose's size (so units and up axis do not matter);
//! * names: one minus the mean best cosine similarity of each joint's name embedding to the
//!   other skeleton's, both ways.
//!
//! A skeleton's score against a model is its smallest total distance to a training skeleton,
//! which is named as the nearest. `LIMIT` is calibrated on measurements (docs/ood.md): held-out
//! zoo skeletons fall inside it, the real captures the built-in model fails on fall outside.

use crate::embed::{cosine, EmbedError, NameTable};
use crate::skeleton::Skeleton;
use glam::DVec3;
use serde::Serialize;

/// Scores above this are out of range (docs/ood.md, the built-in models: every training
/// skeleton lies within 0.20 of another, the held-out dragon_v7 scores 0.08, the real captures
/// they fail on 0.41-0.84, a 40-bone star of random names 3.0).
pub const LIMIT: f64 = 0.25;

/// The limit for a skeleton `mo-sample` samples with a model's unseen-skeleton denoiser
/// (`diffusion::unseen`), which moves skeletons the main denoiser stands still. Calibrated on the
/// built-in pair's zero-shot samples of twelve real captures (docs/ood.md): the four whose
/// samples meet issue 22's bars score 0.27-0.45 (and the Flamingo, 0.57), the seven that do not
/// 0.52-0.84.
pub const UNSEEN_LIMIT: f64 = 0.48;

/// What one skeleton is compared on.
#[derive(Clone, Debug)]
pub struct Profile {
    pub name: String,
    /// Per joint, each sorted: depth, child count, height above the deepest leaf below.
    graph: [Vec<f64>; 3],
    /// Per non-root joint, sorted: bone length and rest distance from the root, over the size.
    shape: [Vec<f64>; 2],
    names: Vec<Vec<f32>>,
}

impl Profile {
    /// From a joint list: names, parents (each before its children) and rest offsets.
    pub fn new(name: &str, joints: &[String], parents: &[Option<usize>], offsets: &[DVec3], table: &NameTable) -> Profile {
        let n = joints.len().min(parents.len()).min(offsets.len());
        let mut depth = vec![0usize; n];
        let mut children = vec![0usize; n];
        let mut position = vec![DVec3::ZERO; n];
        for j in 0..n {
            if let Some(p) = parents[j].filter(|&p| p < j) {
                depth[j] = depth[p] + 1;
                children[p] += 1;
                position[j] = position[p] + offsets[j];
            }
        }
        // Height above the deepest leaf: children come after parents, so one backward pass.
        let mut height = vec![0usize; n];
        for j in (0..n).rev() {
            if let Some(p) = parents[j].filter(|&p| p < j) {
                height[p] = height[p].max(height[j] + 1);
            }
        }
        let (lo, hi) = position.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let size = if n > 1 { (hi - lo).max_element().max(1e-9) } else { 1.0 };
        let non_root = || (0..n).filter(|&j| parents[j].is_some_and(|p| p < j));
        let sorted = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v
        };
        Profile {
            name: name.to_string(),
            graph: [
                sorted(depth.iter().map(|&d| d as f64).collect()),
                sorted(children.iter().map(|&c| c as f64).collect()),
                sorted(height.iter().map(|&h| h as f64).collect()),
            ],
            shape: [sorted(non_root().map(|j| offsets[j].length() / size).collect()), sorted(non_root().map(|j| position[j].length() / size).collect())],
            names: joints[..n].iter().map(|j| table.embed_name(j)).collect(),
        }
    }

    pub fn of_skeleton(name: &str, s: &Skeleton, table: &NameTable) -> Profile {
        let names: Vec<String> = s.joints.iter().map(|j| j.name.clone()).collect();
        let offsets: Vec<DVec3> = s.joints.iter().map(|j| j.offset).collect();
        Profile::new(name, &names, &s.parents(), &offsets, table)
    }
}

/// How far apart two skeletons are, in parts.
#[derive(Clone, Copy, Debug, Default, Serialize, PartialEq)]
pub struct Distance {
    /// The sum of the parts; reported once, as `Score::score`.
    #[serde(skip)]
    pub total: f64,
    pub graph: f64,
    pub proportions: f64,
    pub names: f64,
}

/// 1-D Wasserstein distance between two sorted samples (the area between their quantile
/// functions); 0 when either is empty.
fn wasserstein(a: &[f64], b: &[f64]) -> f64 {
    if a.is_empty() || b.is_empty() {
        return 0.0;
    }
    // Walk the merged breakpoints of both quantile functions.
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let (mut i, mut j, mut q, mut area) = (0usize, 0usize, 0.0f64, 0.0f64);
    while i < a.len() && j < b.len() {
        let next = ((i + 1) as f64 / na).min((j + 1) as f64 / nb);
        area += (next - q) * (a[i] - b[j]).abs();
        q = next;
        if (i + 1) as f64 / na <= next + 1e-12 {
            i += 1;
        }
        if (j + 1) as f64 / nb <= next + 1e-12 {
            j += 1;
        }
    }
    area
}

fn mean(v: &[f64]) -> f64 {
    if v.is_empty() {
        0.0
    } else {
        v.iter().sum::<f64>() / v.len() as f64
    }
}

/// The mean, over `a`'s joints, of the best cosine similarity to a joint of `b`.
fn name_match(a: &[Vec<f32>], b: &[Vec<f32>]) -> f64 {
    if a.is_empty() || b.is_empty() {
        return 0.0;
    }
    a.iter().map(|x| b.iter().map(|y| cosine(x, y) as f64).fold(f64::NEG_INFINITY, f64::max)).sum::<f64>() / a.len() as f64
}

pub fn distance(a: &Profile, b: &Profile) -> Distance {
    let relative = |x: &[f64], y: &[f64]| wasserstein(x, y) / mean(x).max(mean(y)).max(1.0);
    let joints = |p: &Profile| p.graph[0].len().max(1) as f64;
    let count = (joints(a) / joints(b)).ln().abs();
    let graph = (relative(&a.graph[0], &b.graph[0]) + wasserstein(&a.graph[1], &b.graph[1]) + relative(&a.graph[2], &b.graph[2]) + count) / 4.0;
    // Both shape samples lie in [0, 1]; a distance of 0.25 is already a very different body.
    let proportions = 2.0 * (wasserstein(&a.shape[0], &b.shape[0]) + wasserstein(&a.shape[1], &b.shape[1]));
    let names = (1.0 - 0.5 * (name_match(&a.names, &b.names) + name_match(&b.names, &a.names))).max(0.0);
    Distance { total: graph + proportions + names, graph, proportions, names }
}

/// A skeleton's place against a model's training skeletons.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Score {
    /// The distance to the nearest training skeleton (`Distance::total`).
    pub score: f64,
    /// Scores above this are out of range (reports give it once, beside their skeletons).
    #[serde(skip)]
    pub limit: f64,
    pub in_range: bool,
    /// The nearest training skeleton, and the parts of the distance to it.
    pub nearest: String,
    pub parts: Distance,
}

/// Name, joint names, parents and rest offsets of one recorded training skeleton.
pub type Recorded<'a> = (&'a str, &'a [String], &'a [Option<usize>], &'a [[f64; 3]]);

/// The training skeletons of a model, profiled once.
pub struct Reference {
    pub profiles: Vec<Profile>,
    /// Scores above this are out of range: `LIMIT` unless set (`with_limit`).
    pub limit: f64,
}

impl Reference {
    /// None when the model records no skeletons (then nothing can be said).
    pub fn score(&self, p: &Profile) -> Option<Score> {
        let (nearest, parts) = self.profiles.iter().map(|t| (t, distance(p, t))).min_by(|x, y| x.1.total.total_cmp(&y.1.total))?;
        Some(Score { score: parts.total, limit: self.limit, in_range: parts.total <= self.limit, nearest: nearest.name.clone(), parts })
    }

    /// The same skeletons judged against another limit (`UNSEEN_LIMIT` for sampling with an
    /// unseen-skeleton denoiser).
    pub fn with_limit(self, limit: f64) -> Reference {
        Reference { limit, ..self }
    }

    /// The training skeletons as a model records them (name, joint names, parents, rest
    /// offsets), profiled with the built-in name table; a record whose offsets do not match its
    /// joints is left out.
    pub fn from_records<'a>(records: impl Iterator<Item = Recorded<'a>>) -> Result<Reference, EmbedError> {
        let table = NameTable::builtin()?;
        let profiles = records
            .filter(|(_, joints, _, offsets)| offsets.len() == joints.len())
            .map(|(name, joints, parents, offsets)| {
                Profile::new(name, joints, parents, &offsets.iter().map(|o| DVec3::from_array(*o)).collect::<Vec<_>>(), table)
            })
            .collect();
        Ok(Reference { profiles, limit: LIMIT })
    }

    /// `skeleton`'s score (named `label`; None when the model records no skeletons).
    pub fn score_skeleton(&self, label: &str, skeleton: &Skeleton) -> Result<Option<Score>, EmbedError> {
        Ok(self.score(&Profile::of_skeleton(label, skeleton, NameTable::builtin()?)))
    }

    /// The report `mo-metrics ood` prints: each skeleton's score against this reference (the
    /// training skeletons of `model`), the limit, and with `training` each training skeleton's
    /// nearest other one.
    pub fn report(&self, model: &str, skeletons: &[(String, Skeleton)], training: bool) -> Result<serde_json::Value, EmbedError> {
        use serde_json::{json, Value};
        let mut scored = Vec::new();
        for (name, skeleton) in skeletons {
            scored.push(json!({ "skeleton": name, "ood": self.score_skeleton(name, skeleton)? }));
        }
        let mut report = json!({ "model": model, "limit": self.limit, "skeletons": scored });
        if training {
            let within: Vec<Value> = self.nearest_within().into_iter().map(|(a, b, d)| json!({ "skeleton": a, "nearest": b, "distance": d })).collect();
            report["training"] = Value::Array(within);
        }
        Ok(report)
    }

    /// Each training skeleton with the other one it is closest to, and their distance.
    pub fn nearest_within(&self) -> Vec<(String, String, f64)> {
        (0..self.profiles.len())
            .filter_map(|i| {
                let (j, d) = (0..self.profiles.len())
                    .filter(|&j| j != i)
                    .map(|j| (j, distance(&self.profiles[i], &self.profiles[j]).total))
                    .min_by(|x, y| x.1.total_cmp(&y.1))?;
                Some((self.profiles[i].name.clone(), self.profiles[j].name.clone(), d))
            })
            .collect()
    }
}

/// The one-line warning for an out-of-range score (None in range): how far out, the nearest
/// training skeleton, and `advice`, what to do instead.
pub fn warning(tool: &str, skeleton: &str, model: &str, s: &Score, advice: &str) -> Option<String> {
    (!s.in_range).then(|| {
        format!(
            "{tool}: warning: {skeleton} is out of {model}'s training range (OOD score {:.2}, limit {:.2}; nearest trained skeleton {}): expect poor results; {advice}",
            s.score, s.limit, s.nearest
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wasserstein_of_shifted_samples_is_the_shift() {
        assert_eq!(wasserstein(&[0.0, 1.0, 2.0], &[0.0, 1.0, 2.0]), 0.0);
        assert!((wasserstein(&[0.0, 1.0, 2.0], &[0.5, 1.5, 2.5]) - 0.5).abs() < 1e-12);
        // Different sizes: {0, 1} against {0, 0, 1, 1} is the same distribution.
        assert!(wasserstein(&[0.0, 1.0], &[0.0, 0.0, 1.0, 1.0]).abs() < 1e-12);
        assert!((wasserstein(&[0.0], &[1.0, 3.0]) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn a_skeleton_is_nearest_itself_and_a_star_is_far_out() {
        let table = NameTable::builtin().unwrap();
        let zoo: Vec<Profile> = ["quadruped", "biped", "spider", "snake"]
            .iter()
            .map(|n| {
                let (s, _) = crate::synth::creature(n, 0).unwrap();
                Profile::of_skeleton(n, &s, table)
            })
            .collect();
        let reference = Reference { profiles: zoo.clone(), limit: LIMIT };
        for p in &zoo {
            let s = reference.score(p).unwrap();
            assert_eq!((s.nearest.as_str(), s.score, s.in_range), (p.name.as_str(), 0.0, true));
        }
        // A variant of a trained creature is in range and nearest its family.
        let (variant, _) = crate::synth::creature("quadruped", 3).unwrap();
        let s = reference.score(&Profile::of_skeleton("q3", &variant, table)).unwrap();
        assert!(s.in_range && s.nearest == "quadruped", "{s:?}");
        // As the built-in model is trained: variants 0-6 of every family; the held-out
        // variant 7 of each is in range, nearest its own family.
        let families = ["quadruped", "biped", "spider", "snake", "centipede", "crab", "dragon", "bird", "fish"];
        let mut trained = Vec::new();
        for f in families {
            for v in 0..7 {
                let (s, _) = crate::synth::creature(f, v).unwrap();
                trained.push(Profile::of_skeleton(&format!("{f}_v{v}"), &s, table));
            }
        }
        let zoo = Reference { profiles: trained, limit: LIMIT };
        for f in families {
            let (s, _) = crate::synth::creature(f, 7).unwrap();
            let score = zoo.score(&Profile::of_skeleton(f, &s, table)).unwrap();
            assert!(score.in_range && score.nearest.starts_with(f), "{f}_v7: {score:?}");
        }
        // 40 bones of random names all hanging from the root.
        let names: Vec<String> = std::iter::once("root".to_string()).chain((0..40).map(|i| format!("zq{}x{}", i * 7919 % 97, i))).collect();
        let parents: Vec<Option<usize>> = std::iter::once(None).chain((0..40).map(|_| Some(0))).collect();
        let offsets: Vec<DVec3> = (0..41).map(|i| DVec3::new((i as f64).cos(), (i as f64).sin(), 0.1 * i as f64)).collect();
        let star = reference.score(&Profile::new("star", &names, &parents, &offsets, table)).unwrap();
        assert!(!star.in_range && star.score > 2.0 * LIMIT, "{star:?}");
        assert!(
            warning("mo-sample", "star", "the built-in model", &star, "use --examples").is_some_and(|w| w.contains("out of") && w.ends_with("use --examples"))
        );
    }
}
