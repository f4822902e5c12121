//! The JSON that `mo-dift` prints for two motions: joint matches, frame matches and the binding
//! read off DIFT joint matches. It is here, not in the tool, so that a library caller who has
//! the features of two clips gets the same report, row for row and digit for digit, as the tool.

use super::correspond::{best_matches, binding_choices, cosine_matrix, monotonic_matches, Match};
use super::{centred, frame_descriptors, DiftError, DiftFeatures};
use crate::binding::auto;
use crate::binding::clips::{self, ClipBindError};
use crate::correspond;
use crate::motion::Clip;
use crate::skeleton::Skeleton;
use serde_json::{json, Value};

/// The paper's binding rate, what `--features dift-only --as-binding` binds by default.
pub const DIFT_BIND_RATE: f64 = 0.061;

/// How frame matches are chosen: in time order (one monotonic path) or each frame's best
/// (`mo-dift --align`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Align {
    /// In time order (dynamic time warping): the answers never go back.
    Monotonic,
    /// Each target frame on its own: the most similar reference frame (the paper's rule).
    Nearest,
}

/// One target joint's answer (a struct, so the fields print in this order).
#[derive(serde::Serialize)]
struct JointRow {
    target: String,
    target_index: usize,
    reference: String,
    reference_index: usize,
    score: f64,
    margin: f64,
    /// The engine's confidence and whether the pair is one to one (absent with dift-only).
    #[serde(skip_serializing_if = "Option::is_none")]
    confidence: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    one_to_one: Option<bool>,
}

/// One target frame's answer.
#[derive(serde::Serialize)]
struct FrameRow {
    target: usize,
    reference: usize,
    score: f64,
    margin: f64,
}

fn joint_row(m: &Match, reference: &Clip, target: &Clip) -> JointRow {
    JointRow {
        target: target.skeleton.joints[m.target].name.clone(),
        target_index: m.target,
        reference: reference.skeleton.joints[m.reference].name.clone(),
        reference_index: m.reference,
        score: round(m.score),
        margin: round(m.margin),
        confidence: None,
        one_to_one: None,
    }
}

/// Four decimals: scores are cosines; more digits are noise to a reader.
fn round(v: f64) -> f64 {
    (v * 1e4).round() / 1e4
}

/// Pretty JSON with a final newline.
fn pretty(v: Value) -> String {
    let mut s = serde_json::to_string_pretty(&v).unwrap_or_else(|_| v.to_string());
    s.push('\n');
    s
}

/// One skeleton in two files: the same joints (names and parents) in the same order; bone
/// lengths may differ.
fn same_skeleton(a: &Skeleton, b: &Skeleton) -> bool {
    a.len() == b.len() && a.joints.iter().zip(&b.joints).all(|(x, y)| x.name == y.name && x.parent == y.parent)
}

/// The settings block of a report on DIFT features: the two clips, the feature options and the
/// model's label.
pub fn settings(reference: &Clip, target: &Clip, options: &super::DiftOptions, model: &str) -> Value {
    json!({
        "reference": reference.name, "target": target.name, "t": options.t, "layer": options.layer, "draws": options.draws,
        "model": model,
    })
}

/// Each target joint's best reference joint by DIFT features (`features`: reference, target).
pub fn joint_matches(reference: &Clip, target: &Clip, features: [&DiftFeatures; 2], settings: Value) -> String {
    let sim = cosine_matrix(&centred(features[1].per_joint()), &centred(features[0].per_joint()));
    let rows = best_matches(&sim).iter().map(|m| joint_row(m, reference, target)).collect::<Vec<_>>();
    pretty(json!({ "correspondence": "joints", "settings": settings, "matches": rows }))
}

/// The binding JSON of the DIFT joint matches that are each other's best, at most `rate`.
pub fn joint_binding(reference: &Clip, target: &Clip, features: [&DiftFeatures; 2], rate: f64) -> Result<String, DiftError> {
    let sim = cosine_matrix(&centred(features[1].per_joint()), &centred(features[0].per_joint()));
    let choices = binding_choices(&sim, &reference.skeleton, &target.skeleton, rate, auto::AutoOptions::default().min_pairs);
    if choices.is_empty() {
        return Err(DiftError::Invalid(format!(
            "{} and {}: no joint pair is each other's best match among the joints that move a bone; nothing to bind",
            reference.name, target.name
        )));
    }
    Ok(auto::to_binding(&choices, &reference.skeleton, &reference.name, &target.skeleton, &target.name).to_json())
}

/// Each target frame's reference frame by DIFT features (joints side by side on one skeleton,
/// else averaged over joints).
pub fn frame_matches(reference: &Clip, target: &Clip, features: [&DiftFeatures; 2], mut settings: Value, align: Align) -> String {
    let same = same_skeleton(&reference.skeleton, &target.skeleton);
    settings["align"] = json!(if align == Align::Monotonic { "monotonic" } else { "nearest" });
    settings["descriptors"] = json!(if same { "joints side by side" } else { "mean over joints" });
    let (r, t) = frame_descriptors(features[0], features[1], same);
    let sim = cosine_matrix(&t, &r);
    let matches = match align {
        Align::Monotonic => monotonic_matches(&sim),
        Align::Nearest => best_matches(&sim),
    };
    let rows: Vec<_> = matches.iter().map(|m| FrameRow { target: m.target, reference: m.reference, score: round(m.score), margin: round(m.margin) }).collect();
    pretty(json!({ "correspondence": "frames", "settings": settings, "matches": rows }))
}

/// Joint matches of the `correspond` engine (no model): every target joint that found a
/// partner, with its confidence and whether the pair is one to one.
pub fn combined_joint_matches(reference: &Clip, target: &Clip) -> Result<String, ClipBindError> {
    let scores = clips::joint_scores(reference, target)?;
    let pairs = correspond::assign(&scores);
    let rows: Vec<JointRow> = correspond::per_target(&scores, &pairs)
        .into_iter()
        .filter_map(|(_, found)| found)
        .map(|(p, one_to_one)| {
            let m = Match { target: p.target, reference: p.source, score: p.score, margin: p.margin };
            JointRow { confidence: Some(round(p.confidence)), one_to_one: Some(one_to_one), ..joint_row(&m, reference, target) }
        })
        .collect();
    let header = json!({ "reference": reference.name, "target": target.name, "features": "combined" });
    Ok(pretty(json!({ "correspondence": "joints", "settings": header, "matches": rows })))
}

/// The binding of the `correspond` engine (what `mo-retarget --bind auto` uses), as JSON.
pub fn combined_binding(reference: &Clip, target: &Clip, rate: Option<f64>) -> Result<String, ClipBindError> {
    let choices = clips::bind_auto(reference, target, rate)?;
    Ok(auto::to_binding(&choices, &reference.skeleton, &reference.name, &target.skeleton, &target.name).to_json())
}
