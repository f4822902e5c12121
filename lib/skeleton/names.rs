//! Readable, normalised joint names.
//!
//! Joint names feed a text embedding (AnyTop conditions on them) and name-based matching
//! (bindings, feet, sides), so the many spellings of one body part should become one string:
//! `LeftFoot`, `l_foot`, `Bip01_L_Foot`, `Foot_L`, `mixamorig:LeftFoot` and
//! `Bip01_L_Foot__ouF` all normalise to "Left Foot". Rules, after docs/reference/anytop.md §1.11
//! and beyond it:
//!
//! 1. drop a namespace (`mixamorig:`) and a random Truebones suffix (`__xyz`);
//! 2. split at `_ - . :` and spaces, before capitals (`LeftUpLeg`, `LHipJoint` -> L Hip Joint)
//!    and between letters and digits;
//! 3. drop leading rig prefixes (`Bip01`, `BN`, `NPC`, `jt`, `ORG`, `DEF`, `MCH`, `joint`...);
//! 4. drop numbers (`readable` keeps them as ordinals) and one-letter words, except `L`/`R`
//!    which become Left/Right; translate
//!    AnyTop's Japanese words (`momo` -> Thigh ...) and `Tai` -> Tail; split `lhand` -> l hand
//!    for a few body words;
//! 5. move the side word to the front, capitalise each word, join with spaces.
//!
//! Deviation from AnyTop: the side word is moved to the front (AnyTop keeps `Shoulder Left`
//! and `Left Shoulder` apart) and lower-case words are capitalised.

/// Rig prefixes that carry no meaning, dropped while they lead the name.
const RIG_PREFIXES: &[&str] =
    &["bip01", "bip001", "bip", "bn", "npc", "jt", "org", "def", "mch", "joint", "jnt", "bone", "mixamorig", "sabrecat", "elk", "cc", "base", "rig"];

const JAPANESE: &[(&str, &str)] = &[
    ("momo", "Thigh"),
    ("sippo", "Tail"),
    ("mune", "Chest"),
    ("hiza", "Knee"),
    ("hara", "Stomach"),
    ("ashi", "Leg"),
    ("hiji", "Elbow"),
    ("koshi", "Hips"),
    ("te", "Hand"),
    ("kubi", "Neck"),
    ("atama", "Head"),
    ("ago", "Jaw"),
    ("kata", "Shoulder"),
];

/// Body words recognised after a glued side letter (`lhand`, `rfoot`, `lshoulder`).
const GLUED_SIDE_WORDS: &[&str] = &[
    "hand", "foot", "arm", "leg", "shoulder", "hip", "knee", "elbow", "wrist", "ankle", "toe", "toes", "thigh", "finger", "fingers", "thumb", "collar",
    "clavicle", "upleg", "forearm", "uparm", "wing", "eye", "ear",
];

/// Which side a normalised name says.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    Left,
    Right,
    Centre,
}

/// Split a raw name into words (rules 1-2): no namespace, no Truebones suffix, split at
/// separators, case changes and digit runs.
pub fn split_words(raw: &str) -> Vec<String> {
    let mut s = raw;
    if let Some(i) = s.rfind(':') {
        if i + 1 < s.len() {
            s = &s[i + 1..];
        }
    }
    // Truebones random suffix: `__` followed by exactly three alphanumerics at the end.
    if let Some(i) = s.rfind("__") {
        let tail = &s[i + 2..];
        if i > 0 && tail.len() == 3 && tail.chars().all(|c| c.is_ascii_alphanumeric()) {
            s = &s[..i];
        }
    }
    let chars: Vec<char> = s.chars().collect();
    let mut words = Vec::new();
    let mut cur = String::new();
    for (k, &c) in chars.iter().enumerate() {
        if matches!(c, '_' | '-' | '.' | ' ' | ':' | '|' | '/') {
            if !cur.is_empty() {
                words.push(std::mem::take(&mut cur));
            }
            continue;
        }
        if let Some(&prev) = cur.chars().last().as_ref() {
            let next = chars.get(k + 1).copied();
            let boundary = (prev.is_lowercase() && c.is_uppercase())
                || (prev.is_alphabetic() && c.is_ascii_digit())
                || (prev.is_ascii_digit() && c.is_alphabetic())
                // `LHip`: split before the last capital of a run that is followed by lower case.
                || (prev.is_uppercase() && c.is_uppercase() && next.is_some_and(|n| n.is_lowercase()));
            if boundary {
                words.push(std::mem::take(&mut cur));
            }
        }
        cur.push(c);
    }
    if !cur.is_empty() {
        words.push(cur);
    }
    words
}

/// Drop leading rig prefixes (rule 3; also `Bip01` split as `Bip` + `01`), keeping one word.
pub(crate) fn drop_rig_prefixes(words: &mut Vec<String>) {
    while words.len() > 1 {
        let w = words[0].to_ascii_lowercase();
        if RIG_PREFIXES.contains(&w.as_str()) || w.chars().all(|c| c.is_ascii_digit()) {
            words.remove(0);
        } else {
            break;
        }
    }
}

/// What one lower-case word of a name is (rule 4), shared by `normalise` and the
/// correspondence key (`correspond::names`), which keep different parts of it.
pub(crate) enum Word<'a> {
    Number,
    Side(Side),
    /// A translated word (`momo` -> Thigh, `tai` -> Tail).
    Known(&'static str),
    /// A side letter glued to a body word (`lhand`): the side and the body word.
    Glued(Side, &'a str),
    Plain,
}

pub(crate) fn classify(lower: &str) -> Word<'_> {
    if lower.chars().all(|c| c.is_ascii_digit()) {
        return Word::Number;
    }
    match lower {
        "l" | "left" => return Word::Side(Side::Left),
        "r" | "right" => return Word::Side(Side::Right),
        _ => {}
    }
    if let Some((_, en)) = JAPANESE.iter().find(|(jp, _)| *jp == lower) {
        return Word::Known(en);
    }
    if lower == "tai" {
        return Word::Known("Tail");
    }
    if lower.len() > 2 && (lower.starts_with('l') || lower.starts_with('r')) && GLUED_SIDE_WORDS.contains(&&lower[1..]) {
        return Word::Glued(if lower.starts_with('l') { Side::Left } else { Side::Right }, &lower[1..]);
    }
    Word::Plain
}

/// The normalised name of a raw joint name, numbers dropped: the key of the name embeddings
/// (`embed`). The built-in models were trained on exactly these strings, so it stays as it is;
/// `leg_l1_coxa` ... `leg_l4_coxa` all give "Left Leg Coxa" here. For people and for matching
/// use `readable`, which keeps the ordinals.
pub fn normalise(raw: &str) -> String {
    joined(raw, false)
}

/// The readable name of a raw joint name: `normalise` with the numbers kept in place, without
/// leading zeros (`leg_l1_coxa` -> "Left Leg 1 Coxa", `Tail_03` -> "Tail 3", `Spine1` ->
/// "Spine 1"), so that four legs or three spine joints do not read as one. What `skel-info`
/// shows as `normalised`.
pub fn readable(raw: &str) -> String {
    joined(raw, true)
}

fn joined(raw: &str, numbers: bool) -> String {
    let mut words = split_words(raw);
    drop_rig_prefixes(&mut words);
    let mut side: Option<Side> = None;
    let mut out: Vec<String> = Vec::new();
    for w in &words {
        let lower = w.to_ascii_lowercase();
        match classify(&lower) {
            Word::Number if numbers => out.push(match lower.trim_start_matches('0') {
                "" => "0".to_string(),
                digits => digits.to_string(),
            }),
            Word::Number => {}
            Word::Side(s) => {
                side.get_or_insert(s);
            }
            Word::Known(en) => out.push(en.to_string()),
            Word::Glued(s, body) => {
                side.get_or_insert(s);
                out.push(capitalise(body));
            }
            Word::Plain if w.chars().count() == 1 => {}
            Word::Plain => out.push(capitalise(w)),
        }
    }
    if out.is_empty() && side.is_none() {
        // Nothing survived (e.g. `Bip01`): keep the raw name minus namespace so it stays unique-ish.
        return split_words(raw).join(" ");
    }
    let mut parts: Vec<String> = side.map(|s| if s == Side::Left { "Left" } else { "Right" }.to_string()).into_iter().collect();
    parts.extend(out);
    parts.join(" ")
}

fn capitalise(w: &str) -> String {
    let mut c = w.chars();
    match c.next() {
        Some(f) => f.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}

/// The side a normalised name states, if any.
pub fn side_from_name(normalised: &str) -> Option<Side> {
    match normalised.split(' ').next() {
        Some("Left") => Some(Side::Left),
        Some("Right") => Some(Side::Right),
        _ => None,
    }
}

/// The key that left and right partners share: the raw name without namespace, Truebones
/// suffix and side words, lower case.
pub fn mirror_key(raw: &str) -> String {
    split_words(raw).into_iter().map(|w| w.to_lowercase()).filter(|w| !matches!(w.as_str(), "l" | "r" | "left" | "right")).collect::<Vec<_>>().join("_")
}

#[cfg(test)]
mod tests {
    use super::{normalise, readable};

    #[test]
    fn readable_names_keep_ordinals_and_tell_legs_apart() {
        assert_eq!(readable("leg_l1_coxa"), "Left Leg 1 Coxa");
        assert_eq!(readable("Tail_03"), "Tail 3");
        assert_eq!(readable("Bip01_R_Finger0"), "Right Finger 0");
        assert_eq!(readable("mixamorig:LeftHandIndex1"), "Left Hand Index 1");
        assert_eq!(readable("Bip01_L_Foot__ouF"), "Left Foot");
        // What the issue saw: the embedding key still merges the four legs, the readable name
        // does not, on the spider and the centipede.
        assert_eq!(normalise("leg_l1_coxa"), normalise("leg_l4_coxa"));
        for creature in ["spider", "centipede"] {
            let (skeleton, _) = crate::synth::creature(creature, 0).unwrap();
            let names: Vec<String> = skeleton.joints.iter().map(|j| readable(&j.name)).collect();
            let mut unique = names.clone();
            unique.sort();
            unique.dedup();
            assert_eq!(unique.len(), names.len(), "{creature}: {names:?}");
            let keys: std::collections::BTreeSet<String> = skeleton.joints.iter().map(|j| normalise(&j.name)).collect();
            assert!(keys.len() < names.len(), "{creature}: the embedding key merges legs");
        }
    }

    #[test]
    fn spellings_of_one_part_agree() {
        for raw in ["LeftFoot", "l_foot", "Bip01_L_Foot", "Foot_L", "mixamorig:LeftFoot", "Bip01_L_Foot__ouF", "BN_Bip01_L_Foot"] {
            assert_eq!(normalise(raw), "Left Foot", "{raw}");
        }
    }

    #[test]
    fn anytop_examples_and_corpus_styles() {
        let cases = [
            ("BN_Bip01_L_Thigh", "Left Thigh"),
            ("BN_Finger_R_01", "Right Finger"),
            ("RLeg1", "Right Leg"),
            ("LeftUpLeg", "Left Up Leg"),
            ("l_momo", "Left Thigh"),
            ("jtTail3", "Tail"),
            ("LHipJoint", "Left Hip Joint"),
            ("lhand", "Left Hand"),
            ("RThumb", "Right Thumb"),
            ("DEF_BN_Leg_L_15_end", "Left Leg End"),
            ("joint_Root", "Root"),
            ("Bip01_R_HorseLink__kyi", "Right Horse Link"),
            ("mixamorig:HeadTop_End", "Head Top End"),
            ("Hips", "Hips"),
            ("Bip01", "Bip 01"),
        ];
        for (raw, want) in cases {
            assert_eq!(normalise(raw), want, "{raw}");
        }
    }
}
