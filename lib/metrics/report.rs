//! The JSON reports `mo-metrics` prints, built from clips: every number named, units in a
//! `units` table, and the same report as aligned text for humans (`table`).
//!
//! The metrics themselves are the sibling modules; this module puts them together the way the
//! papers' tables do (which clips against which, windows for the FIDs, baselines for movement),
//! so that a library caller gets the very report the tool prints.

use super::fid::{fid, FidOptions};
use super::generation::{self, GenerationOptions, PointClip};
use super::physics::{self, PhysicsOptions};
use super::{geometric, kinetic, movement, reconstruction, transfer, MetricError, WorldClip};
use crate::document::AnyTopSection;
use crate::motion::Clip;
use crate::repr::anytop::{AnyTopError, RigError};
use serde_json::{json, Map, Value};

/// Why a report could not be made; messages name the clip.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error(transparent)]
    Metric(#[from] MetricError),
    /// A metric failed on one clip (or one step), named by `what`.
    #[error("{what}")]
    Within {
        what: String,
        #[source]
        source: MetricError,
    },
    #[error("{name}: cannot encode")]
    Encode {
        name: String,
        #[source]
        source: AnyTopError,
    },
    #[error(transparent)]
    Rig(#[from] RigError),
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// Clips that cannot be compared, or a report that is not one, said in one sentence.
    #[error("{0}")]
    Invalid(String),
    #[error(transparent)]
    Read(#[from] crate::io::ReadError),
}

fn invalid(message: String) -> ReportError {
    ReportError::Invalid(message)
}

/// A metric's error, put in the context of `what` (a clip's name, a step).
fn within(what: &str) -> impl Fn(MetricError) -> ReportError + '_ {
    move |source| ReportError::Within { what: what.to_string(), source }
}

/// A loaded motion as world positions, with a defined error for non-finite values.
pub fn world_clip(l: &Clip) -> Result<WorldClip, ReportError> {
    let clip = WorldClip::from_motion(&l.skeleton, &l.motion);
    if let Some((f, j)) = clip.first_non_finite() {
        return Err(invalid(format!("{}: non-finite position at frame {f}, joint {j} '{}'", l.name, l.skeleton.joints[j].name)));
    }
    Ok(clip)
}

/// Units of every number the reports hold, by key.
pub fn units(keys: &[(&str, &str)]) -> Value {
    let mut m = Map::new();
    for (k, u) in keys {
        m.insert(k.to_string(), json!(u));
    }
    Value::Object(m)
}

/// `mo-metrics physics`: the physics report of every clip.
pub fn physics_report(loaded: &[Clip], opts: &PhysicsOptions) -> Result<Value, ReportError> {
    use rayon::prelude::*;
    let reports: Vec<Result<Value, ReportError>> = loaded
        .par_iter()
        .map(|l| {
            let clip = world_clip(l)?;
            let report = physics::physics(&clip, opts).map_err(within(&l.name))?;
            let mut v = serde_json::to_value(&report)?;
            if let Value::Object(m) = &mut v {
                m.insert("file".into(), json!(l.name));
            }
            Ok(v)
        })
        .collect();
    let files = reports.into_iter().collect::<Result<Vec<Value>, ReportError>>()?;
    Ok(json!({
        "metric": "physics",
        "files": files,
    }))
}

/// `mo-metrics reconstruction`: SATA's reconstruction metrics of `b` against `a`, clips of one
/// skeleton and one length; `height` scales the retargeting error.
pub fn reconstruction_report(a: &Clip, b: &Clip, height: f64) -> Result<Value, ReportError> {
    let (ca, cb) = (world_clip(a)?, world_clip(b)?);
    let counted = reconstruction::rotation_joints(&a.skeleton);
    let rotations = reconstruction::Rotations { reference: &a.motion.rotations, result: &b.motion.rotations, counted };
    let report = reconstruction::reconstruction(&ca, &cb, Some(&rotations), height, &PhysicsOptions::default())
        .map_err(|source| ReportError::Within { what: format!("{} vs {}", a.name, b.name), source })?;
    Ok(json!({
        "metric": "reconstruction",
        "reference": a.name,
        "result": b.name,
        "report": report,
    }))
}

/// What `transfer_report` compares: results against their source through bound joint pairs.
pub struct Transfer<'a> {
    pub source: &'a Clip,
    /// On one target skeleton.
    pub results: &'a [Clip],
    /// Source joint -> target joint.
    pub pairs: &'a [(usize, usize)],
    /// The target's example clips, the real set of the FIDs (may be empty).
    pub examples: &'a [Clip],
    /// Seconds the results took to make, for throughput.
    pub seconds: Option<f64>,
    /// Window length of the FID sets (0: whole clips).
    pub fid_window: usize,
}

/// `mo-metrics transfer`: Motion2Motion's transfer metrics of every result, their diversity,
/// throughput and (with examples) the FIDs.
pub fn transfer_report(t: &Transfer) -> Result<Value, ReportError> {
    let (src, results, pairs, examples, seconds, fid_window) = (t.source, t.results, t.pairs, t.examples, t.seconds, t.fid_window);
    let target = &results[0];
    let src_clip = world_clip(src)?;
    let clips = results.iter().map(world_clip).collect::<Result<Vec<WorldClip>, ReportError>>()?;
    let mut per_result = Vec::new();
    for (l, c) in results.iter().zip(&clips) {
        let freq = transfer::frequency_alignment(&src_clip, c, pairs).map_err(within(&l.name))?;
        let contact = transfer::contact_consistency(&src_clip, c, pairs, &PhysicsOptions::default()).map_err(within(&l.name))?;
        let motion = transfer::motion_ratio(&src_clip, c, pairs).map_err(within(&l.name))?;
        per_result.push(json!({ "file": l.name, "frequency_alignment": freq, "contact_consistency": contact, "motion_ratio": motion }));
    }
    let mut out = json!({
        "metric": "transfer",
        "source": src.name,
        "bound_pairs": pairs.len(),
        "results": per_result,
    });
    let m = out.as_object_mut().expect("object");
    m.insert(
        "diversity".into(),
        match transfer::diversity(&clips) {
            Ok(d) => serde_json::to_value(d)?,
            Err(e) => json!({ "not_applicable": e.to_string() }),
        },
    );
    if let Some(s) = seconds {
        let frames: usize = clips.iter().map(|c| c.frames).sum();
        m.insert("throughput".into(), json!(transfer::throughput(frames, s)?));
    }
    if !examples.is_empty() {
        let ex = examples;
        for e in ex {
            if e.skeleton.len() != target.skeleton.len() {
                return Err(invalid(format!(
                    "example {} has {} joints but the results have {}: the examples are clips of the target skeleton",
                    e.name,
                    e.skeleton.len(),
                    target.skeleton.len()
                )));
            }
        }
        let ex_clips = ex.iter().map(world_clip).collect::<Result<Vec<WorldClip>, ReportError>>()?;
        let (ex_sets, result_sets) = (windows(&ex_clips, fid_window), windows(&clips, fid_window));
        let kin = |cs: &[WorldClip]| -> Result<Vec<Vec<f64>>, ReportError> {
            cs.iter().map(|c| kinetic::kinetic_features(c).map_err(within("kinetic features"))).collect()
        };
        m.insert("fid_kinetic".into(), fid_value(&kin(&ex_sets)?, &kin(&result_sets)?)?);
        let fid_g = match geometric::human_roles(&clips[0]) {
            Ok(roles) => {
                let opts = geometric::GeometricOptions::default();
                let g = |cs: &[WorldClip]| -> Result<Vec<Vec<f64>>, ReportError> {
                    cs.iter().map(|c| Ok(geometric::geometric_features(c, &roles, &opts)?)).collect()
                };
                fid_value(&g(&ex_sets)?, &g(&result_sets)?)?
            }
            Err(why) => json!({ "not_applicable": format!("no human roles on the target skeleton: {why}") }),
        };
        m.insert("fid_geometric".into(), fid_g);
    }
    m.insert(
        "units".into(),
        units(&[
            ("frequency_alignment", "cosine similarity in [0, 1]"),
            ("contact_consistency", "fraction of frames in [0, 1]"),
            ("motion_ratio", "result speed over source speed, each per skeleton size (1 = moves as much)"),
            ("diversity", "target length units"),
            ("throughput", "result frames per second"),
            ("fid_kinetic", "Fréchet distance of normalised features (dimensionless)"),
            ("fid_geometric", "Fréchet distance of normalised features (dimensionless)"),
        ]),
    );
    Ok(out)
}

/// Clips cut into consecutive windows of `len` frames (the remainder dropped); `len` 0 keeps
/// whole clips.
fn windows(clips: &[WorldClip], len: usize) -> Vec<WorldClip> {
    if len == 0 {
        return clips.to_vec();
    }
    let mut out = Vec::new();
    for c in clips {
        for k in 0..c.frames / len {
            let mut w = c.clone();
            w.frames = len;
            w.positions = c.positions[k * len * c.joints..(k + 1) * len * c.joints].to_vec();
            out.push(w);
        }
    }
    out
}

/// FID, or why it has no value (too few clips), as JSON.
fn fid_value(real: &[Vec<f64>], generated: &[Vec<f64>]) -> Result<Value, ReportError> {
    // One vector has no covariance: the distance would only say the two means differ, and
    // normalising by the real set's spread is impossible.
    if real.len() < 2 || generated.len() < 2 {
        return Ok(json!({ "not_applicable": format!(
            "FID needs at least 2 real and 2 generated clips, found {} and {}: give more clips or --fid-window FRAMES",
            real.len(),
            generated.len()
        ) }));
    }
    Ok(match fid(real, generated, &FidOptions::default()) {
        Ok(f) => serde_json::to_value(f)?,
        Err(MetricError::TooLittle(why)) => json!({ "not_applicable": why }),
        Err(e) => return Err(e.into()),
    })
}

/// Joints of the target whose normalised name matches a source joint's.
pub fn same_name_pairs(src: &Clip, tgt: &Clip) -> Vec<(usize, usize)> {
    use crate::skeleton::lookup::find_joint;
    (0..src.skeleton.len()).filter_map(|i| find_joint(&tgt.skeleton, &src.skeleton.joints[i].name).ok().map(|j| (i, j))).collect()
}

/// `mo-metrics generation`: AnyTop's generation metrics of `gen` against `gt`, all clips of
/// one skeleton encoded with one rig (`section`), and the movement block.
pub fn generation_report(gt: &[Clip], gen: &[Clip], section: &AnyTopSection, opts: &GenerationOptions) -> Result<Value, ReportError> {
    let first = &gt[0];
    let points = |ls: &[Clip]| -> Result<Vec<PointClip>, ReportError> {
        use rayon::prelude::*;
        ls.par_iter().map(|l| point_clip(section, l)).collect()
    };
    let (gt_points, gen_points) = (points(gt)?, points(gen)?);
    let report = generation::generation_metrics(&gen_points, &gt_points, opts)?;
    let movement = movement_report(gt, gen, &gt_points, &gen_points, opts.seed)?;
    Ok(json!({
        "metric": "generation",
        "skeleton": first.name,
        "gt_clips": gt.len(),
        "generated_samples": gen.len(),
        "report": report,
        "movement": movement,
        "units": units(&[
            ("coverage", "percent of ground-truth windows"),
            ("energy", "body sizes per second (joints relative to the root, 5-frame average)"),
            ("energy_ratio", "energy / the clips' mean energy"),
            ("energy_ratio_range", "lowest and highest ratio of one motion"),
            ("nearest_pose", "pairwise joint distances / body size, mean absolute difference"),
            ("calibrated_coverage", "percent of ground-truth windows within the calibrated threshold"),
            ("calibrated_coverage_by_clip", "the same per ground-truth clip, in the order of movement.clips (null: the clip left out, or too short for a window)"),
            ("threshold", "mean joint distance, AnyTop units (a quantile of the clips' own nearest-window distances)"),
            ("duty_factor", "share of frames a foot is in contact"),
            ("mixed_contact", "share of frames with some feet down and some up"),
            ("alternation", "share of the feet's horizontal swing that is against a partner foot, not with it (1: a walk's left against right, 0: all together)"),
            ("footfall_error", "cycles, 0-0.5: the feet's phases against each other, from the nearest clip stretch's (0: the clips' footfall order)"),
            ("footfall_chance", "cycles: footfall_error of feet phased at random"),
            ("swing", "-1 to 1: lifted feet move with the root's travel (1, a walk) or against it (-1, the legs played backwards)"),
            ("local_diversity", "mean joint distance, AnyTop units (mean SMPL bone = 0.209)"),
            ("global_diversity", "mean joint distance per frame, AnyTop units"),
            ("inter_diversity", "mean joint distance, AnyTop units"),
            ("intra_diversity", "mean joint distance, AnyTop units"),
            ("gt_intra_diversity", "mean joint distance, AnyTop units"),
            ("intra_diversity_diff", "mean joint distance, AnyTop units"),
        ]),
    }))
}

/// The movement metrics (`metrics::movement`) of the samples and of baselines made from the
/// clips: the clips left out one at a time, their static mean pose and random crops (at
/// least as many as the samples, two per clip) as long as the samples.
fn movement_report(gt: &[Clip], gen: &[Clip], gt_points: &[PointClip], gen_points: &[PointClip], seed: u64) -> Result<Value, ReportError> {
    let world = |ls: &[Clip]| -> Result<Vec<WorldClip>, ReportError> { ls.iter().map(world_clip).collect() };
    let (gt_world, gen_world) = (world(gt)?, world(gen)?);
    let reference = movement::Reference::new(&gt_world, gt_points, &movement::MovementOptions::default()).map_err(within("movement metrics"))?;
    let frames = gen_world.iter().map(|c| c.frames).max().unwrap_or(120);
    let count = gen_world.len();
    let samples = reference.score(&gen_world, gen_points, None)?;
    let clips = reference.clips_baseline()?;
    let (mean_world, mean_points) = reference.mean_pose(count, frames);
    let mean_pose = reference.score(&mean_world, &mean_points, None)?;
    let (crop_world, crop_points) = reference.random_crops(count, frames, seed);
    let crops = reference.score(&crop_world, &crop_points, None)?;
    Ok(json!({
        "clips": gt.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(),
        "threshold": reference.threshold,
        "footfall_chance": reference.footfall_chance(seed),
        "samples": samples,
        "baselines": { "clips": clips, "mean_pose": mean_pose, "random_crops": crops },
    }))
}

/// The metrics a generation report carries, in table order.
const GENERATION_METRICS: [&str; 7] =
    ["coverage", "local_diversity", "global_diversity", "inter_diversity", "intra_diversity", "gt_intra_diversity", "intra_diversity_diff"];

/// The JSON reports in `paths` (`-` = stdin), each with its file's name, for `aggregate_report`.
pub fn read_reports(paths: &[std::path::PathBuf]) -> Result<Vec<(String, Value)>, ReportError> {
    let read = |path: &std::path::PathBuf| {
        let (name, bytes) = crate::io::read_named(path)?;
        let value = serde_json::from_slice(&bytes).map_err(|e| invalid(format!("{name}: not JSON: {e}")))?;
        Ok((name, value))
    };
    paths.iter().map(read).collect()
}

/// `mo-metrics aggregate`: mean and std over skeletons of the per-skeleton means of generation
/// reports (each with the name of the file it came from).
pub fn aggregate_report(reports: &[(String, Value)]) -> Result<Value, ReportError> {
    let mut skeletons = Vec::new();
    let mut means: Vec<Vec<f64>> = vec![Vec::new(); GENERATION_METRICS.len()];
    for (name, v) in reports {
        if v.get("metric").and_then(Value::as_str) != Some("generation") {
            return Err(invalid(format!("{name}: not a report of `mo-metrics generation` (no \"metric\": \"generation\")")));
        }
        for (k, key) in GENERATION_METRICS.iter().enumerate() {
            let m = v["report"][key]["mean"].as_f64().ok_or_else(|| invalid(format!("{name}: report.{key}.mean is missing or not a number")))?;
            means[k].push(m);
        }
        skeletons.push(v["skeleton"].as_str().unwrap_or(name).to_string());
    }
    let mut fin = Map::new();
    for (k, key) in GENERATION_METRICS.iter().enumerate() {
        fin.insert(key.to_string(), serde_json::to_value(generation::MeanStd::of(&means[k]))?);
    }
    Ok(json!({
        "metric": "generation-aggregate",
        "skeletons": skeletons,
        "final": fin,
        "units": units(&[("coverage", "percent of ground-truth windows"), ("local_diversity", "AnyTop units"), ("global_diversity", "AnyTop units"),
            ("inter_diversity", "AnyTop units"), ("intra_diversity", "AnyTop units"), ("gt_intra_diversity", "AnyTop units"), ("intra_diversity_diff", "AnyTop units")]),
    }))
}

/// AnyTop's evaluation features of one clip: joints 1..J-1, dims 0..3 of the 13-D features
/// (root-relative x, z in the facing frame; y absolute), with y minus the root height.
fn point_clip(section: &AnyTopSection, l: &Clip) -> Result<PointClip, ReportError> {
    if l.motion.frames < 2 {
        return Err(invalid(format!("{}: {} frame(s): generation metrics need clips of at least two frames", l.name, l.motion.frames)));
    }
    let encoded = section.rig.encode(&l.skeleton, &l.motion).map_err(|source| ReportError::Encode { name: l.name.clone(), source })?;
    let f = &encoded.features;
    PointClip::from_anytop_features(f.frames, f.joints, &f.data).map_err(within(&l.name))
}

/// A JSON report as aligned `name  value  unit` lines, for humans.
pub fn table(report: &Value) -> String {
    // Every `units` table in the report, inner ones (the library's) over outer ones.
    fn gather(v: &Value, into: &mut Map<String, Value>) {
        match v {
            Value::Object(m) => {
                if let Some(Value::Object(u)) = m.get("units") {
                    into.extend(u.clone());
                }
                m.iter().filter(|(k, _)| *k != "units").for_each(|(_, x)| gather(x, into));
            }
            Value::Array(a) => a.iter().for_each(|x| gather(x, into)),
            _ => {}
        }
    }
    let mut units = Map::new();
    gather(report, &mut units);
    let mut rows: Vec<(String, String, String)> = Vec::new();
    flatten("", report, &units, &mut rows);
    let w0 = rows.iter().map(|r| r.0.len()).max().unwrap_or(0);
    // Numbers line up; a long string (a file name) does not widen the column for all.
    let w1 = rows.iter().map(|r| r.1.len()).filter(|&l| l <= 24).max().unwrap_or(0);
    let mut out = String::new();
    for (k, v, u) in rows {
        let line = format!("{k:<w0$}  {v:<w1$}  {u}");
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

fn flatten(prefix: &str, v: &Value, units: &Map<String, Value>, rows: &mut Vec<(String, String, String)>) {
    // The unit of a leaf is its own key's, or its parent's for the parts of a measure.
    let unit_of = |key: &str| -> String {
        let parts: Vec<&str> = key.split('.').map(|p| p.split('[').next().unwrap_or(p)).collect();
        let leaf = parts.last().copied().unwrap_or("");
        let owner = match leaf {
            "value" | "mean" | "std" | "per_pair" | "normalised" if parts.len() >= 2 => parts[parts.len() - 2],
            _ => leaf,
        };
        let unit = units.get(owner).and_then(Value::as_str).unwrap_or("");
        if leaf == "normalised" {
            unit.replace("clip length units", "skeleton sizes").replace("target length units", "skeleton sizes")
        } else {
            unit.to_string()
        }
    };
    match v {
        Value::Object(m) => {
            for (k, x) in m {
                if k == "units" {
                    continue;
                }
                let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}.{k}") };
                flatten(&key, x, units, rows);
            }
        }
        Value::Array(a) if a.iter().all(|x| x.is_number() || x.is_string()) && a.len() <= 16 => {
            let text = a.iter().map(|x| x.as_str().map_or_else(|| fmt_number(x), str::to_string)).collect::<Vec<_>>().join(", ");
            rows.push((prefix.to_string(), format!("[{text}]"), unit_of(prefix)));
        }
        Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                flatten(&format!("{prefix}[{i}]"), x, units, rows);
            }
        }
        Value::Number(_) => rows.push((prefix.to_string(), fmt_number(v), unit_of(prefix))),
        Value::String(s) => rows.push((prefix.to_string(), s.clone(), String::new())),
        Value::Bool(b) => rows.push((prefix.to_string(), b.to_string(), String::new())),
        Value::Null => rows.push((prefix.to_string(), "-".into(), String::new())),
    }
}

fn fmt_number(v: &Value) -> String {
    match v.as_f64() {
        Some(x) if v.is_f64() => format!("{x:.6}"),
        _ => v.to_string(),
    }
}
