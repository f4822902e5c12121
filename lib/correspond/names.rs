//! Joint names as correspondence evidence: the side, the body words and the ordinals.
//!
//! `skeleton::names::normalise` drops numbers and one-letter words, so `leg_l1_coxa` ...
//! `leg_l4_coxa` all read "Left Leg Coxa". That string is what the built-in diffusion and latent
//! models were trained on (their name embeddings, `embed`), so it stays as it is: changing it
//! would change what the shipped models receive. Matching joints across skeletons needs what
//! it drops, so this module keeps a richer key beside it: the side, the body words in a
//! canonical spelling (`UpLeg` = `Thigh`, `Collar` = `Clavicle`), and the ordinals (`leg_l1`,
//! `Tail_03`, `Finger0`), compared as numbers (`01` = `1`).
//!
//! It also says which pair of limbs a word belongs to: arm, hand, finger, clavicle, wing are
//! front-limb words; thigh, calf, foot, toe, horselink are hind-limb words.

use crate::skeleton::names::{classify, drop_rig_prefixes, split_words, Side, Word};

/// What a joint's name says, for matching.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NameKey {
    /// The side the name states.
    pub side: Option<Side>,
    /// Body words, lower case, canonical spelling, in name order; no side words, no numbers.
    pub words: Vec<String>,
    /// Numbers in the name after the rig prefix, in order (`leg_l1_coxa` -> [1]).
    pub ordinals: Vec<u64>,
    /// The whole name in lower case, without namespace and Truebones suffix: two joints whose
    /// keys agree but whose spellings differ (Rigify's `ORG_Pelvis` and `DEF_Pelvis`) are told
    /// apart by it.
    pub spelling: String,
    /// Rigify's bone layer when the name starts with one (`org`, `def`, `mch`): the same body
    /// part in two layers is two bones (the original and its deform copy), so two names that
    /// agree but for their layer are a weaker match than two that agree and share no layer word.
    pub layer: Option<String>,
}

/// Rigify's bone layers, as name prefixes.
const LAYERS: &[&str] = &["org", "def", "mch"];

impl NameKey {
    /// A name that says nothing (numbers only, or a bare rig prefix): no evidence.
    pub fn is_blank(&self) -> bool {
        self.words.is_empty()
    }
}

/// Two-word spellings of one part, and single-word synonyms, mapped to one word.
const PHRASES: &[(&str, &str, &str)] = &[
    ("up", "leg", "thigh"),
    ("up", "arm", "upperarm"),
    ("upper", "arm", "upperarm"),
    ("fore", "arm", "forearm"),
    ("horse", "link", "horselink"),
    ("toe", "base", "toe"),
];
const SYNONYMS: &[(&str, &str)] = &[("upleg", "thigh"), ("uparm", "upperarm"), ("toes", "toe"), ("fingers", "finger"), ("collar", "clavicle")];

/// Words of the front limbs (arms, wings) and of the hind limbs (legs).
const FRONT_WORDS: &[&str] =
    &["arm", "upperarm", "forearm", "hand", "finger", "thumb", "index", "middle", "ring", "pinky", "clavicle", "shoulder", "elbow", "wrist", "wing", "palm"];
const HIND_WORDS: &[&str] = &["thigh", "calf", "foot", "toe", "horselink", "knee", "ankle", "shin", "leg"];

/// Which pair of limbs a word names, if it names one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LimbWord {
    Front,
    Hind,
}

/// The key of a raw joint name.
pub fn key(raw: &str) -> NameKey {
    let mut words = split_words(raw);
    let spelling = words.join("_").to_ascii_lowercase();
    let prefixed = words.clone();
    drop_rig_prefixes(&mut words);
    let dropped = prefixed.len() - words.len();
    let layer = prefixed.into_iter().take(dropped).map(|w| w.to_ascii_lowercase()).find(|w| LAYERS.contains(&w.as_str()));
    let mut out = NameKey { spelling, layer, ..NameKey::default() };
    let mut body: Vec<String> = Vec::new();
    for w in &words {
        let lower = w.to_ascii_lowercase();
        match classify(&lower) {
            // Too many digits to be an ordinal: a number is still a number, saturated.
            Word::Number => out.ordinals.push(lower.parse().unwrap_or(u64::MAX)),
            Word::Side(s) => {
                out.side.get_or_insert(s);
            }
            Word::Known(en) => body.push(en.to_ascii_lowercase()),
            Word::Glued(s, part) => {
                out.side.get_or_insert(s);
                body.push(part.to_string());
            }
            Word::Plain if lower.chars().count() == 1 => {}
            Word::Plain => body.push(lower),
        }
    }
    // Phrases first (`up leg`), then single-word synonyms.
    let mut i = 0;
    while i < body.len() {
        if let Some(&(_, _, one)) = body.get(i + 1).and_then(|next| PHRASES.iter().find(|(a, b, _)| *a == body[i] && b == next)) {
            body[i] = one.to_string();
            body.remove(i + 1);
        }
        if let Some((_, one)) = SYNONYMS.iter().find(|(w, _)| *w == body[i]) {
            body[i] = one.to_string();
        }
        i += 1;
    }
    out.words = body;
    if out.words.is_empty() {
        // A number alone (a renamed joint) is an index, not an ordinal of a body part.
        out.ordinals.clear();
    }
    out
}

/// Which limb pair the words name: the last word that names one (`LeftHandThumb` -> front).
pub fn limb_word(key: &NameKey) -> Option<LimbWord> {
    key.words.iter().rev().find_map(|w| {
        if FRONT_WORDS.contains(&w.as_str()) {
            Some(LimbWord::Front)
        } else if HIND_WORDS.contains(&w.as_str()) {
            Some(LimbWord::Hind)
        } else {
            None
        }
    })
}

/// The similarity of one body part's names in two Rigify layers (`ORG_Pelvis`, `DEF_Pelvis`):
/// above any partial match (at most 0.8) and below the same part without layer words (1), so
/// that the right layer wins by 0.25 rather than by the spelling's 0.1, which the rest-pose
/// terms could outweigh (a skel-aug variant of the Crab paired `ORG_BN_Bip01_Pelvis` with
/// `DEF_BN_Bip01_Pelvis`, its child at the same place).
const LAYER_MISMATCH: f64 = 0.85;

/// How alike two names are, 0..1.1: 1 for the same side, words and ordinals (1.1 when spelt
/// the same too, `LAYER_MISMATCH` when they name two Rigify layers of that part); otherwise the share of words in common, lowered when both carry ordinals
/// that differ. `None` when either name says nothing.
pub fn similarity(a: &NameKey, b: &NameKey) -> Option<f64> {
    if a.is_blank() || b.is_blank() {
        return None;
    }
    if a.words == b.words && a.ordinals == b.ordinals && a.side == b.side {
        let other_layer = matches!((&a.layer, &b.layer), (Some(x), Some(y)) if x != y);
        return Some(if a.spelling == b.spelling {
            1.1
        } else if other_layer {
            LAYER_MISMATCH
        } else {
            1.0
        });
    }
    let shared = a.words.iter().filter(|w| b.words.contains(w)).count();
    let union = a.words.len() + b.words.len() - shared;
    let mut s = 0.8 * shared as f64 / union.max(1) as f64;
    if !a.ordinals.is_empty() && !b.ordinals.is_empty() {
        // Same words, other number (leg 1 vs leg 3): a different part of the same kind.
        s *= if a.ordinals == b.ordinals { 1.0 } else { 0.4 };
    }
    Some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ordinals_and_sides_survive() {
        let k = key("leg_l1_coxa");
        assert_eq!((k.side, k.words.clone(), k.ordinals.clone()), (Some(Side::Left), vec!["leg".to_string(), "coxa".into()], vec![1]));
        assert_ne!(key("leg_l1_coxa"), key("leg_l4_coxa"));
        assert_eq!(key("Leg01_L").ordinals, vec![1]);
        assert_eq!(key("Tail_03").ordinals, key("tail3").ordinals);
        let finger = key("Bip01_R_Finger0__abc");
        assert_eq!((finger.side, finger.words.clone(), finger.ordinals.clone()), (Some(Side::Right), vec!["finger".to_string()], vec![0]));
        // Renamed joints: a bare number is no name at all.
        assert!(key("17").is_blank() && key("17").ordinals.is_empty());
    }

    #[test]
    fn spellings_agree_and_limb_words_say_front_or_hind() {
        assert_eq!(key("LeftUpLeg").words, key("Bip01_L_Thigh").words);
        assert_eq!(key("mixamorig:LeftForeArm").words, key("l_forearm").words);
        assert_eq!(limb_word(&key("Bip01_R_HorseLink")), Some(LimbWord::Hind));
        assert_eq!(limb_word(&key("Bip01_L_Finger0")), Some(LimbWord::Front));
        assert_eq!(limb_word(&key("LeftCollar")), Some(LimbWord::Front));
        assert_eq!(limb_word(&key("Spine1")), None);
        assert_eq!(similarity(&key("LeftFoot"), &key("Bip01_L_Foot__ouF")), Some(1.0));
        assert_eq!(similarity(&key("mixamorig:LeftFoot"), &key("LeftFoot")), Some(1.1));
        let near = similarity(&key("leg_l1_femur"), &key("leg_l3_femur")).unwrap();
        let same_leg = similarity(&key("leg_l1_femur"), &key("leg_l1_tibia")).unwrap();
        assert!(near < 1.0 && near > 0.0 && same_leg > 0.0, "{near} {same_leg}");
        assert_eq!(similarity(&key("3"), &key("Hips")), None);
        // Rigify layers: the same layer (or none) beats another layer of the same part.
        assert_eq!(key("ORG_BN_Bip01_Pelvis").layer.as_deref(), Some("org"));
        assert_eq!(key("Pelvis").layer, None);
        let same = similarity(&key("ORG_BN_Bip01_Pelvis"), &key("ORG_BN_Bip01_Pelvis")).unwrap();
        let other = similarity(&key("ORG_BN_Bip01_Pelvis"), &key("DEF_BN_Bip01_Pelvis")).unwrap();
        let plain = similarity(&key("ORG_BN_Bip01_Pelvis"), &key("Bip01_Pelvis")).unwrap();
        assert!(same > plain && plain > other && other > 0.8, "{same} {plain} {other}");
    }
}
