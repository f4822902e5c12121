//! Joint correspondence where the truth is known (issue 24): top-1 accuracy, left/right and
//! front/hind confusions of names only, geometry only (rest pose and topology), DIFT only (the
//! paper's matching, `mo-dift --features dift-only`) and the combined engine (`correspond`,
//! what `mo-dift --joints` and `--bind auto` use), on
//!
//! * corpus pairs that share a naming scheme, truth = the same joint name (Truebones suffixes
//!   and namespaces dropped): Flamingo/Chicken, Elephant/Monkey, Chicken/Elephant, Joe/Malcolm,
//!   LAFAN1/dog;
//! * CMU <-> Xia: one tree in one file order, names that disagree (CMU's LeftShoulder is Xia's
//!   LeftArm): truth = the same place in the tree;
//! * corpus clips against copies renamed with numbers and shuffled (`dift::eval::renamed_shuffled`);
//! * corpus clips against skel-aug variants (surviving joints keep their names);
//! * the zoo: each family's example creature against its proportion variants 1 and 2
//!   (`synth::training_clip`), renamed and shuffled.
//!
//!     cargo bench --bench correspond                  # built-in model for the DIFT column
//!
//! The corpus rows need ../shared/data (skipped with a message when absent). Clips are cut to
//! their first 120 frames. "combined + DIFT" adds DIFT cosine as extra evidence
//! (`correspond::EXTRA_WEIGHT`), a column to decide whether the tools should. CORRESPOND_DEBUG=1
//! prints every wrong answer on stderr.
mod common;

use candle_core::Device;
use menagerie::augment::{self, RemoveAmount};
use menagerie::bvh;
use menagerie::correspond::describe::{describe, Limb, Roles};
use menagerie::correspond::{self, Body, Evidence};
use menagerie::diffusion::checkpoint::{self, FrozenDenoiser};
use menagerie::dift::correspond::{best_matches, cosine_matrix};
use menagerie::dift::{self, eval, DiftOptions};
use menagerie::document::AnyTopSection;
use menagerie::motion::Motion;
use menagerie::repr::anytop::RigOptions;
use menagerie::rng::SplitMix64;
use menagerie::skeleton::names::Side;
use menagerie::skeleton::Skeleton;
use menagerie::synth;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const MAX_FRAMES: usize = 120;
const METHODS: [&str; 5] = ["names only", "geometry only", "DIFT only", "combined", "combined + DIFT"];

struct Clip {
    name: String,
    skeleton: Skeleton,
    motion: Motion,
}

fn read(path: &Path) -> Option<Clip> {
    let parsed = bvh::read_path(path).ok()?;
    let skeleton = Skeleton::from_bvh(&parsed);
    skeleton.validate().ok()?;
    let motion = Motion::from_bvh(&parsed, &skeleton).first_frames(MAX_FRAMES);
    Some(Clip { name: path.file_name()?.to_string_lossy().into_owned(), skeleton, motion })
}

fn first_in(dir: &Path) -> Option<Clip> {
    if dir.is_file() {
        return read(dir);
    }
    common::bvh_files(dir).iter().find_map(|p| read(p))
}

fn rest(s: &Skeleton, m: &Motion) -> Option<Vec<glam::DVec3>> {
    let section = AnyTopSection::new(s, &m.first_frames(2), &RigOptions::default()).ok()?;
    Some(section.rig.rest_positions(s))
}

/// A joint name without a Truebones suffix or a namespace.
fn bare(name: &str) -> String {
    let n = name.rsplit(':').next().unwrap_or(name);
    match n.rfind("__") {
        Some(i) if n.len() - i == 5 => n[..i].to_string(),
        _ => n.to_string(),
    }
}

#[derive(Clone, Copy, Default)]
struct Score {
    correct: usize,
    total: usize,
    left_right: usize,
    front_hind: usize,
}

/// DIFT per-joint descriptors (the `mo-dift --joints` defaults: t 2, layer 0, 4 draws, centred).
fn dift_rows(model: &FrozenDenoiser, c: &Clip) -> Option<Vec<Vec<f32>>> {
    let prepared = dift::prepare(&model.info, &c.skeleton, &c.motion, &c.name).ok()?;
    let f =
        dift::extract(&model.model, &model.info.schedule(), &prepared.condition.condition(), &prepared.features, &DiftOptions::SPATIAL, &Device::Cpu).ok()?;
    Some(dift::centred(f.per_joint()))
}

/// Score every method on reference `a` vs target `b` with `truth[target] = reference joint`.
fn score_pair(model: Option<&FrozenDenoiser>, a: &Clip, b: &Clip, truth: &[Option<usize>]) -> Option<Vec<Score>> {
    let (ra, rb) = (rest(&a.skeleton, &a.motion)?, rest(&b.skeleton, &b.motion)?);
    let (ba, bb) = (Body { skeleton: &a.skeleton, rest: &ra }, Body { skeleton: &b.skeleton, rest: &rb });
    // The reference's own sides and limb pairs (names and rest pose) judge the confusions.
    let judge = describe(&a.skeleton, &ra, true, Roles::Names);
    let dift_sim: Option<Vec<Vec<f64>>> = model.and_then(|m| Some(cosine_matrix(&dift_rows(m, b)?, &dift_rows(m, a)?)));
    let mut out = Vec::new();
    for method in METHODS {
        // Per target joint, the answer (a reference joint) if any.
        let answers: Vec<Option<usize>> = match method {
            "DIFT only" => match &dift_sim {
                Some(sim) => {
                    let mut ans = vec![None; b.skeleton.len()];
                    for m in best_matches(sim) {
                        ans[m.target] = Some(m.reference);
                    }
                    ans
                }
                None => vec![None; b.skeleton.len()],
            },
            _ => {
                let (evidence, extra) = match method {
                    "names only" => (Evidence::NAMES, None),
                    "geometry only" => (Evidence::GEOMETRY, None),
                    "combined" => (Evidence::ALL, None),
                    _ => match &dift_sim {
                        // [target][reference] -> [source = reference][target].
                        Some(sim) => {
                            (Evidence::ALL, Some((0..a.skeleton.len()).map(|r| (0..b.skeleton.len()).map(|t| sim[t][r]).collect()).collect::<Vec<Vec<f64>>>()))
                        }
                        None => (Evidence::ALL, None),
                    },
                };
                let scores = correspond::scores(&ba, &bb, evidence, extra.as_deref()).ok()?;
                let pairs = correspond::assign(&scores);
                correspond::per_target(&scores, &pairs).into_iter().map(|(_, p)| p.map(|(p, _)| p.source)).collect()
            }
        };
        let mut s = Score::default();
        for (t, truth) in truth.iter().enumerate() {
            let Some(right) = *truth else { continue };
            s.total += 1;
            match answers[t] {
                Some(got) if got == right => s.correct += 1,
                Some(got) => {
                    if std::env::var_os("CORRESPOND_DEBUG").is_some() {
                        eprintln!("{method}: {} -> {} (truth {})", b.skeleton.joints[t].name, a.skeleton.joints[got].name, a.skeleton.joints[right].name);
                    }
                    if matches!((judge.side[got], judge.side[right]), (Side::Left, Side::Right) | (Side::Right, Side::Left)) {
                        s.left_right += 1;
                    }
                    if matches!((judge.limb[got], judge.limb[right]), (Limb::Front, Limb::Hind) | (Limb::Hind, Limb::Front)) {
                        s.front_hind += 1;
                    }
                }
                None => {}
            }
        }
        out.push(s);
    }
    Some(out)
}

fn renamed(c: &Clip, rng: &mut SplitMix64) -> (Clip, Vec<Option<usize>>) {
    let (s, m, order) = eval::renamed_shuffled(&c.skeleton, &c.motion, rng);
    (Clip { name: format!("{} renamed", c.name), skeleton: s, motion: m }, order.into_iter().map(Some).collect())
}

fn main() {
    let model = match checkpoint::frozen_default(&Device::Cpu) {
        Ok(m) => Some(m),
        Err(e) => {
            println!("(no built-in model, DIFT columns empty: {e:#})");
            None
        }
    };
    let model = model.as_ref();
    let mut rows: BTreeMap<String, Vec<Score>> = BTreeMap::new();
    let mut add = |row: &str, got: Option<Vec<Score>>, what: &str| {
        let Some(got) = got else {
            println!("(skipped {what}: no rest pose)");
            return;
        };
        let r = rows.entry(row.to_string()).or_insert_with(|| vec![Score::default(); METHODS.len()]);
        for (acc, s) in r.iter_mut().zip(got) {
            acc.correct += s.correct;
            acc.total += s.total;
            acc.left_right += s.left_right;
            acc.front_hind += s.front_hind;
        }
    };
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let corpus = root.join("../shared/data/bvh");
    if corpus.is_dir() {
        let at = |p: &str| first_in(&corpus.join(p));
        let named_pairs = [
            ("truebones_motion2motion/Flamingo", "truebones_anytop/Chicken"),
            ("ganimator/Elephant", "truebones_motion2motion/Monkey"),
            ("truebones_anytop/Chicken", "ganimator/Elephant"),
            ("ganimator/Joe", "ganimator/Malcolm"),
            ("lafan1/walk4_subject1.bvh", "dog_mann/Dog"),
        ];
        for (x, y) in named_pairs {
            let (Some(a), Some(b)) = (at(x), at(y)) else { continue };
            let truth: Vec<Option<usize>> = b.skeleton.joints.iter().map(|t| a.skeleton.joints.iter().position(|r| bare(&r.name) == bare(&t.name))).collect();
            add("1 corpus pairs, shared names (truth: names)", score_pair(model, &a, &b, &truth), x);
        }
        if let (Some(a), Some(b)) = (at("cmu_bvh11/131_01.bvh"), at("xia_dme/neutral_01_000.bvh")) {
            if a.skeleton.parents() == b.skeleton.parents() {
                let truth = (0..b.skeleton.len()).map(Some).collect::<Vec<_>>();
                add("2 CMU <-> Xia (truth: tree position)", score_pair(model, &a, &b, &truth), "cmu");
            }
        }
        let mut rng = SplitMix64::new(7);
        for p in [
            "truebones_motion2motion/Flamingo",
            "truebones_motion2motion/Monkey",
            "ganimator/Elephant",
            "truebones_anytop/Chicken",
            "ganimator/Crab",
            "ganimator/Joe",
            "cmu_bvh11/131_01.bvh",
            "lafan1/walk4_subject1.bvh",
            "dog_mann/Dog",
        ] {
            let Some(a) = at(p) else { continue };
            for _ in 0..2 {
                let (b, truth) = renamed(&a, &mut rng);
                add("3 corpus renamed + shuffled", score_pair(model, &a, &b, &truth), p);
                let opts = augment::Options { remove: Some(RemoveAmount::Random), add: 2, keep_feet: true };
                let plan = augment::plan(&a.skeleton, &opts, &mut rng);
                let m = plan.apply_motion(&a.skeleton, &a.motion);
                let truth = eval::truth_by_name(&a.skeleton, &plan.skeleton);
                let b = Clip { name: format!("{} variant", a.name), skeleton: plan.skeleton, motion: m };
                add("4 corpus skel-aug variants", score_pair(model, &a, &b, &truth), p);
            }
        }
    } else {
        println!("SKIP corpus rows: no {}", corpus.display());
    }
    let mut rng = SplitMix64::new(11);
    for &name in synth::creature_names() {
        let Some(a) = synth::training_clip(name, 0, synth::Action::Walk, 0, MAX_FRAMES) else { continue };
        let a = Clip { name: name.to_string(), skeleton: a.skeleton, motion: a.motion };
        for variant in 1..3 {
            let Some(v) = synth::training_clip(name, variant, synth::Action::Walk, variant, MAX_FRAMES) else { continue };
            if v.skeleton.parents() != a.skeleton.parents() {
                continue;
            }
            let v = Clip { name: format!("{name} v{variant}"), skeleton: v.skeleton, motion: v.motion };
            let (b, truth) = renamed(&v, &mut rng);
            add("5 zoo proportion variants, renamed + shuffled", score_pair(model, &a, &b, &truth), name);
        }
    }
    println!("\n## Joint correspondence: top-1 accuracy % (left/right, front/hind confusions)\n");
    println!("| set (target joints with a truth) | {} |", METHODS.join(" | "));
    println!("|---|{}", "---|".repeat(METHODS.len()));
    for (row, scores) in &rows {
        let cells: Vec<String> =
            scores.iter().map(|s| format!("{:.1} ({}, {})", 100.0 * s.correct as f64 / s.total.max(1) as f64, s.left_right, s.front_hind)).collect();
        println!("| {} (n = {}) | {} |", &row[2..], scores[0].total, cells.join(" | "));
    }
}
