//! Joint-name embeddings (lib/embed.rs): the compiled-in MiniLM table, composition of names it
//! lacks, and coverage of our example creatures and (when present) the real corpus.

use crate::common;

use menagerie::embed::{cosine, dequantise_i8, hash_unit_vector, quantise_i8, NameTable, Source};
use menagerie::skeleton::names::normalise;
use menagerie::skeleton::Skeleton;

fn table() -> &'static NameTable {
    NameTable::builtin().expect("the compiled-in name table parses")
}

fn assert_unit(v: &[f32], what: &str) {
    assert_eq!(v.len(), table().dims(), "{what}: width");
    assert!(v.iter().all(|x| x.is_finite()), "{what}: non-finite value");
    let n = v.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt();
    assert!((n - 1.0).abs() < 1e-4, "{what}: norm {n}");
}

fn skeleton_of(path: &std::path::Path) -> Option<Skeleton> {
    // Names only: parse the hierarchy with an empty motion section (corpus files are large).
    let text = std::fs::read_to_string(path).ok()?;
    let end = text.find("MOTION").unwrap_or(text.len());
    let head = format!("{}MOTION\nFrames: 0\nFrame Time: 0.0333333\n", &text[..end]);
    menagerie::bvh::parse(&head, &path.display().to_string()).ok().map(|b| Skeleton::from_bvh(&b))
}

#[test]
fn asset_loads_with_documented_dims() {
    let t = table();
    assert_eq!(t.dims(), 384);
    assert_eq!(t.model(), "sentence-transformers/all-MiniLM-L6-v2");
    assert!(t.len() > 500, "only {} keys", t.len());
    assert!(t.keys().windows(2).all(|w| w[0] < w[1]), "keys are sorted and unique");
    for k in ["foot", "left foot", "right hand", "tail", "antenna", "mandible", "left up leg"] {
        assert_unit(t.lookup(k).unwrap_or_else(|| panic!("'{k}' missing")), k);
    }
}

#[test]
fn spellings_of_left_foot_agree_and_differ_from_other_parts() {
    let t = table();
    let spellings = ["LeftFoot", "l_foot", "Bip01_L_Foot", "mixamorig:LeftFoot"];
    let vs: Vec<Vec<f32>> = spellings.iter().map(|n| t.embed_name(n)).collect();
    let hand = t.embed_name("RightHand");
    let tail = t.embed_name("Tail_03");
    let right_foot = t.embed_name("RightFoot");
    let mut min_same = f32::INFINITY;
    for a in &vs {
        for b in &vs {
            min_same = min_same.min(cosine(a, b));
        }
    }
    let max_other = vs.iter().map(|a| cosine(a, &hand).max(cosine(a, &tail))).fold(f32::NEG_INFINITY, f32::max);
    let lr = cosine(&vs[0], &right_foot);
    eprintln!(
        "cos: spellings min {min_same:.4}, vs RightHand {:.4}, vs Tail_03 {:.4}, Left vs Right Foot {lr:.4}",
        cosine(&vs[0], &hand),
        cosine(&vs[0], &tail)
    );
    assert!(min_same > max_other, "spellings {min_same} vs others {max_other}");
    assert!(lr < cosine(&vs[0], &vs[1]), "left/right kept apart: {lr}");
    assert!(lr < 0.99, "Left Foot and Right Foot nearly identical: {lr}");
}

#[test]
fn composed_names_keep_meaning_and_side() {
    let t = table();
    // Not in the table: composed from "wing", "upper arm", "tip" plus the side offset.
    let (v, src) = t.embed_name_with_source("DEF-wing_upper_arm_tip.L");
    assert!(matches!(src, Source::Composed { .. }), "{src:?}");
    assert_unit(&v, "composed");
    let right = t.embed_name("DEF-wing_upper_arm_tip.R");
    let wing = t.lookup("left wing").unwrap();
    let foot = t.lookup("left foot").unwrap();
    assert!(cosine(&v, wing) > cosine(&v, foot), "composed wing name is nearer a wing than a foot");
    assert!(cosine(&v, &right) < 0.999, "side changes the composed vector");
    assert!(cosine(&v, t.lookup("left wing tip").unwrap()) > cosine(&right, t.lookup("left wing tip").unwrap()), "nearer its own side");
    // Glued and plural words.
    let (_, src) = t.embed_name_with_source("LowerNeck");
    assert_eq!(src, Source::Composed { used: vec!["lower".into(), "neck".into()], skipped: vec![] }, "LowerNeck splits in the normaliser");
    let (g, src) = t.embed_name_with_source("lowerneckbone");
    assert!(matches!(&src, Source::Composed { used, .. } if used.len() >= 2), "{src:?}");
    assert!(cosine(&g, t.lookup("neck").unwrap()) > 0.5, "glued word still reads as a neck");
    let (_, src) = t.embed_name_with_source("Spine_Whiskers");
    assert!(matches!(&src, Source::Composed { used, skipped } if used.contains(&"whisker".to_string()) && skipped.is_empty()), "{src:?}");
}

#[test]
fn unknown_names_fall_back_deterministically() {
    let t = table();
    let (a, src) = t.embed_name_with_source("Zzqx_Wvvk");
    assert_eq!(src, Source::Fallback);
    assert_unit(&a, "fallback");
    assert_eq!(a, t.embed_name("Zzqx_Wvvk"), "same name, same vector");
    let b = t.embed_name("Qwpf_Xkcd");
    assert!(cosine(&a, &b).abs() < 0.3, "distinct unknown names stay apart");
    assert_unit(&t.embed_name(""), "empty name");
    assert_unit(&t.embed_name("L_Zzqx"), "side + unknown");
    let long = "Toe".repeat(500);
    for odd in ["L", "R_", "__", ":", "Left", "ÄÖÜ_Fuß", "ǅ", "İstanbul", "足_L", "ﬀoot", "lowerneckneckneckneckneck", long.as_str(), "\u{0}\u{fffd}"]
    {
        assert_unit(&t.embed_name(odd), odd);
    }
    let h = hash_unit_vector("abc", 384);
    assert_eq!(h.iter().map(|x| x.to_bits()).collect::<Vec<_>>(), hash_unit_vector("abc", 384).iter().map(|x| x.to_bits()).collect::<Vec<_>>());
}

#[test]
fn examples_names_hit_exactly() {
    // tools/name_embeddings.py normalises the examples' names with a Python port of
    // skeleton::names::normalise; an exact hit for every one shows the port agrees.
    let files = common::example_bvh_files();
    assert!(!files.is_empty());
    let t = table();
    for f in files {
        let sk = skeleton_of(&f).unwrap_or_else(|| panic!("{} parses", f.display()));
        let vs = t.embed_skeleton(&sk);
        assert_eq!(vs.len(), sk.joints.len());
        for (j, v) in sk.joints.iter().zip(&vs) {
            let (_, src) = t.embed_name_with_source(&j.name);
            assert_eq!(src, Source::Exact, "{}: '{}' -> '{}'", f.display(), j.name, normalise(&j.name));
            assert_unit(v, &j.name);
        }
    }
}

#[test]
fn corpus_names_embed_to_unit_vectors() {
    let Some(data) = common::shared_data("corpus_names_embed_to_unit_vectors") else { return };
    let t = table();
    let mut names = std::collections::BTreeSet::new();
    for f in common::corpus_bvh_files(&data) {
        if let Some(sk) = skeleton_of(&f) {
            names.extend(sk.joints.into_iter().map(|j| j.name));
        }
    }
    assert!(!names.is_empty());
    let (mut exact, mut composed, mut fallback) = (0, 0, 0);
    for n in &names {
        let (v, src) = t.embed_name_with_source(n);
        assert_unit(&v, n);
        match src {
            Source::Exact => exact += 1,
            Source::Composed { .. } => composed += 1,
            Source::Fallback => fallback += 1,
        }
    }
    eprintln!("corpus: {} distinct joint names: {exact} exact, {composed} composed, {fallback} fallback", names.len());
    assert!(exact + composed >= names.len() * 95 / 100, "most corpus names are covered by words");
}

#[test]
fn quantisation_round_trip_within_bound() {
    let t = table();
    let dims = t.dims();
    // Rows are unit vectors quantised with step s = max|x|/127: each value is off by <= s/2, so
    // the error norm is <= sqrt(dims) * s / 2 <= sqrt(dims) / 254 (max|x| <= 1) and the cosine
    // to the original is >= sqrt(1 - e^2). Check our quantiser on the table's rows and on
    // pseudo-random unit vectors against that bound and the documented 0.9998.
    let mut worst = 1f32;
    // Near-Gaussian unit vectors (sum of four uniform ones), shaped like MiniLM rows.
    let gaussian = |i: usize| {
        let mut v = vec![0f32; dims];
        for k in 0..4 {
            v.iter_mut().zip(hash_unit_vector(&format!("r{i}-{k}"), dims)).for_each(|(a, b)| *a += b);
        }
        let n = v.iter().map(|x| x * x).sum::<f32>().sqrt();
        v.iter().map(|x| x / n).collect::<Vec<f32>>()
    };
    let rows: Vec<Vec<f32>> = (0..300).map(gaussian).collect();
    for v in &rows {
        let (q, s) = quantise_i8(v);
        let back = dequantise_i8(&q, s);
        let err = v.iter().zip(&back).map(|(a, b)| ((a - b) as f64).powi(2)).sum::<f64>().sqrt();
        assert!(err <= (dims as f64).sqrt() * s as f64 / 2.0 + 1e-6, "error norm {err} over bound");
        worst = worst.min(cosine(v, &back));
    }
    eprintln!("quantisation round trip: worst cosine {worst:.6}");
    assert!(worst > 0.9998, "worst cosine {worst}");
}

#[test]
fn malformed_tables_are_errors() {
    assert!(NameTable::from_bytes(b"").is_err());
    assert!(NameTable::from_bytes(b"NOTMAGIC\0\0\0\0").is_err());
    let good = include_bytes!("../../assets/name_embeddings.bin");
    assert!(NameTable::from_bytes(&good[..good.len() - 1]).is_err(), "truncated");
    let mut extra = good.to_vec();
    extra.push(0);
    assert!(NameTable::from_bytes(&extra).is_err(), "trailing byte");
    let mut bad_header = good.to_vec();
    bad_header[12] = b'[';
    let e = NameTable::from_bytes(&bad_header).err().expect("bad JSON header rejected");
    assert!(e.to_string().contains("header"), "{e}");
    let mut huge = good.to_vec();
    huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    assert!(NameTable::from_bytes(&huge).is_err(), "header length past the end");
}
