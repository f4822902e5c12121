//! Joint-name embedding speed: `cargo bench --bench name_embed`.
//!
//! * parsing the compiled-in table (`NameTable::from_bytes`, what `builtin()` does once);
//! * `NameTable::embed_skeleton` over every joint of `examples/data` (exact hits) and over
//!   names the table lacks (composition).
//!
//! Median of `RUNS` runs, one thread.

mod common;
use common::{bvh_files, median, ms, time_runs, RUNS};

use menagerie::embed::NameTable;
use menagerie::skeleton::Skeleton;
use std::hint::black_box;
use std::path::Path;

const COMPOSED: &[&str] = &["DEF-wing_upper_arm_tip.L", "lowerneckbone", "Spine_Whiskers", "R_Leg3_Dactyl_Nub", "Zzqx_Wvvk", "tail_fin_ray_07"];

fn main() {
    let bytes = include_bytes!("../assets/name_embeddings.bin");
    println!("{:<44} {:>12} {:>8}", "what", "median", "runs");
    let t = time_runs(|| {
        black_box(NameTable::from_bytes(black_box(bytes)).expect("table parses"));
    });
    println!("{:<44} {:>9.2} ms {:>8}", format!("parse table ({} bytes)", bytes.len()), ms(median(&t)), RUNS);
    let table = NameTable::builtin().expect("table parses");
    let skeletons: Vec<Skeleton> = bvh_files(&Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/data"))
        .iter()
        .filter_map(|p| menagerie::bvh::read_path(p).ok().map(|b| Skeleton::from_bvh(&b)))
        .collect();
    let joints: usize = skeletons.iter().map(|s| s.joints.len()).sum();
    let t = time_runs(|| {
        for s in &skeletons {
            black_box(table.embed_skeleton(s));
        }
    });
    println!("{:<44} {:>9.2} us {:>8}", "table: per joint, examples/data (exact)", ms(median(&t)) * 1e3 / joints as f64, RUNS);
    let t = time_runs(|| {
        for n in COMPOSED {
            black_box(table.embed_name(n));
        }
    });
    println!("{:<44} {:>9.2} us {:>8}", "table: per name, composed/fallback", ms(median(&t)) * 1e3 / COMPOSED.len() as f64, RUNS);
}
