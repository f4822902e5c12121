//! `metrics::fid` against the textbook computation in numpy + scipy: `np.cov(rowvar=False)`,
//! `scipy.linalg.sqrtm(S1 @ S2)`, real part, and Bailando's normalisation by the real set's
//! mean and std. Needs python3 with numpy and scipy (`python3 -m pip install numpy scipy`);
//! prints a SKIP line and passes without them. `MENAGERIE_PYTHON` picks another interpreter.

use crate::common;

use menagerie::metrics::fid::{fid, FidOptions};
use menagerie::rng::SplitMix64;
use std::process::Command;

const TEXTBOOK: &str = r#"
import sys, json
try:
    import numpy as np, scipy.linalg
except ImportError as e:
    print("MISSING", e)
    sys.exit(0)
for d in json.load(open(sys.argv[1])):
    a, b = np.array(d["real"], dtype=np.float64), np.array(d["generated"], dtype=np.float64)
    if d["normalise"]:
        mu, sd = a.mean(axis=0), a.std(axis=0)
        a, b = (a - mu) / sd, (b - mu) / sd
    m1, m2 = a.mean(axis=0), b.mean(axis=0)
    s1, s2 = np.atleast_2d(np.cov(a, rowvar=False)), np.atleast_2d(np.cov(b, rowvar=False))
    covmean = scipy.linalg.sqrtm(s1.dot(s2))
    if np.iscomplexobj(covmean):
        covmean = covmean.real
    print(repr(float(((m1 - m2) ** 2).sum() + np.trace(s1) + np.trace(s2) - 2 * np.trace(covmean))))
"#;

/// Real set, generated set, normalise.
type Case<'a> = (&'a [Vec<f64>], &'a [Vec<f64>], bool);

fn python() -> String {
    std::env::var("MENAGERIE_PYTHON").unwrap_or_else(|_| "python3".to_string())
}

/// The textbook FID of every case (real, generated, normalise), in one python run (scipy takes
/// a second to import), or `None` (with a SKIP line) when python3, numpy or scipy is missing.
fn textbook(tag: &str, cases: &[Case]) -> Option<Vec<f64>> {
    let dir = common::tempdir(tag);
    let data = dir.join("sets.json");
    let doc: Vec<serde_json::Value> = cases.iter().map(|(r, g, n)| serde_json::json!({ "real": r, "generated": g, "normalise": n })).collect();
    std::fs::write(&data, serde_json::to_vec(&doc).unwrap()).unwrap();
    let script = dir.join("fid.py");
    std::fs::write(&script, TEXTBOOK).unwrap();
    let Ok(out) = Command::new(python()).arg(&script).arg(&data).output() else {
        common::skip(tag, &format!("cannot run {} (install python3 with numpy and scipy)", python()));
        return None;
    };
    assert!(out.status.success(), "python failed: {}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    if text.starts_with("MISSING") {
        common::skip(tag, &format!("{} lacks numpy or scipy ({}); python3 -m pip install numpy scipy", python(), text.trim()));
        return None;
    }
    let values: Vec<f64> = text.lines().map(|l| l.trim().parse().unwrap_or_else(|e| panic!("python printed {l:?}: {e}"))).collect();
    assert_eq!(values.len(), cases.len(), "python printed {text:?}");
    Some(values)
}

/// Correlated Gaussian-ish data: rows = mixing · uniform noise + offset.
fn mixed_set(n: usize, dims: usize, rank: usize, offset: f64, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = SplitMix64::new(seed);
    let mixing: Vec<f64> = (0..dims * rank).map(|_| rng.range(-1.0, 1.0)).collect();
    (0..n)
        .map(|_| {
            let z: Vec<f64> = (0..rank).map(|_| rng.range(-1.0, 1.0) + rng.range(-1.0, 1.0)).collect();
            (0..dims).map(|i| offset * (1.0 + i as f64 * 0.1) + (0..rank).map(|k| mixing[i * rank + k] * z[k]).sum::<f64>()).collect()
        })
        .collect()
}

fn compare(tag: &str, cases: &[Case]) {
    let Some(want) = textbook(tag, cases) else { return };
    for (i, ((real, generated, normalise), want)) in cases.iter().zip(want).enumerate() {
        let ours = fid(real, generated, &FidOptions { normalise: *normalise }).unwrap();
        let rel = (ours.value - want).abs() / want.abs().max(1e-12);
        eprintln!("{tag} case {i}: ours {} numpy/scipy {want} relative {rel:.2e}", ours.value);
        assert!(rel < 1e-6, "{tag} case {i}: ours {} vs textbook {want} (relative {rel:.2e})", ours.value);
        assert!(want > 0.1, "the sets differ, so the distance must not be ~0");
    }
}

/// One python run for all cases: importing scipy costs about a second.
#[test]
fn fid_matches_numpy_and_scipy() {
    // n > dims with full-rank covariances, plain and normalised.
    let real = mixed_set(200, 12, 12, 0.0, 1);
    let generated = mixed_set(150, 12, 12, 0.3, 2);
    // 10 dims driven by 4 (real) and 3 (generated) factors: both covariances are singular.
    let real_low = mixed_set(120, 10, 4, 0.0, 3);
    let generated_low = mixed_set(90, 10, 3, 0.5, 4);
    compare(
        "fid_matches_numpy_and_scipy",
        &[(&real, &generated, false), (&real, &generated, true), (&real_low, &generated_low, false), (&real_low, &generated_low, true)],
    );
}
