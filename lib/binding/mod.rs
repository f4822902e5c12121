//! Bone bindings: sparse source joint -> target joint pairs that tie two skeletons together
//! (Motion2Motion's "sparse correspondence"). `mo-retarget` uses them to transfer motion and
//! `mo-metrics transfer` to compare source and result.
//!
//! Our file is a superset of the reference's: `{"mapping": [{"source", "target"}]}`, plus a
//! format tag, optional skeleton names and optional per-pair scores, so files written by either
//! tool read in both. Names are resolved with `skeleton::lookup::find_joint` (exact, case,
//! namespace, normalised name; never substrings), and a pair order is kept as written.

pub mod auto;
pub mod clips;

use crate::skeleton::{lookup, Skeleton};
use serde::{Deserialize, Serialize};

/// The format tag our binding files carry.
pub const FORMAT: &str = "menagerie.binding";

/// One bound pair, by name.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pair {
    pub source: String,
    pub target: String,
    /// How sure an automatic binder was (0..1); absent in hand-written files.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub score: Option<f64>,
}

/// A binding file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Binding {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source_name: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_name: Option<String>,
    pub mapping: Vec<Pair>,
}

/// A binding resolved on two skeletons: joint indices, in file order.
pub type JointMap = Vec<(usize, usize)>;

#[derive(Debug, thiserror::Error)]
pub enum BindingError {
    #[error("{file}: not a binding (expected JSON like {{\"mapping\": [{{\"source\": \"Hips\", \"target\": \"pelvis\"}}]}}): {why}")]
    Parse { file: String, why: String },
    #[error("{file}: the binding binds no joints")]
    Empty { file: String },
    #[error("{file}: pair {pair}: {side} joint: {skeleton}: {error}")]
    Name { file: String, pair: usize, side: &'static str, skeleton: String, error: Box<lookup::LookupError> },
    #[error("{file}: pairs {first} and {second} both bind {side} joint '{joint}'")]
    Duplicate { file: String, first: usize, second: usize, side: &'static str, joint: String },
    #[error("cannot read binding {file}")]
    Read {
        file: String,
        #[source]
        source: std::io::Error,
    },
    #[error("{file}: not UTF-8 text")]
    NotText { file: String },
}

impl Binding {
    /// Parse a binding file (ours or the reference's); `file` names it in errors.
    pub fn from_json(text: &str, file: &str) -> Result<Binding, BindingError> {
        let binding: Binding = serde_json::from_str(text).map_err(|e| BindingError::Parse { file: file.to_string(), why: e.to_string() })?;
        if binding.mapping.is_empty() {
            return Err(BindingError::Empty { file: file.to_string() });
        }
        Ok(binding)
    }

    /// Read a binding file (`-` = stdin) and resolve it from `source`'s skeleton to
    /// `target`'s: the joint pairs and the binding as read.
    pub fn read_resolved(path: &std::path::Path, source: &crate::motion::Clip, target: &crate::motion::Clip) -> Result<(JointMap, Binding), BindingError> {
        let file = crate::io::display_name(path);
        let bytes = crate::io::read_input(path).map_err(|source| BindingError::Read { file: file.clone(), source })?;
        let text = String::from_utf8(bytes).map_err(|_| BindingError::NotText { file: file.clone() })?;
        let binding = Binding::from_json(&text, &file)?;
        Ok((binding.resolve(&file, &source.skeleton, &source.name, &target.skeleton, &target.name)?, binding))
    }

    /// Pretty JSON with our format tag, one pair per line group.
    pub fn to_json(&self) -> String {
        let mut out = self.clone();
        out.format = Some(FORMAT.to_string());
        let mut text = serde_json::to_string_pretty(&out).expect("a binding always serialises");
        text.push('\n');
        text
    }

    /// Joint indices of every pair on `source` and `target` (named `source_file` and
    /// `target_file` in errors). A joint bound twice on the same side is an error: it would
    /// ask one joint to follow two.
    pub fn resolve(&self, file: &str, source: &Skeleton, source_file: &str, target: &Skeleton, target_file: &str) -> Result<JointMap, BindingError> {
        let mut map = Vec::with_capacity(self.mapping.len());
        for (i, pair) in self.mapping.iter().enumerate() {
            let find = |skeleton: &Skeleton, name: &str, side: &'static str, skeleton_file: &str| {
                lookup::find_joint(skeleton, name).map_err(|error| BindingError::Name {
                    file: file.to_string(),
                    pair: i,
                    side,
                    skeleton: skeleton_file.to_string(),
                    error: Box::new(error),
                })
            };
            let s = find(source, &pair.source, "source", source_file)?;
            let t = find(target, &pair.target, "target", target_file)?;
            map.push((s, t));
        }
        for (side, pick, skeleton) in [("source", 0, source), ("target", 1, target)] {
            for i in 0..map.len() {
                let key = |k: usize| if pick == 0 { map[k].0 } else { map[k].1 };
                if let Some(first) = (0..i).find(|&k| key(k) == key(i)) {
                    return Err(BindingError::Duplicate { file: file.to_string(), first, second: i, side, joint: skeleton.joints[key(i)].name.clone() });
                }
            }
        }
        Ok(map)
    }

    /// Motion2Motion's binding rate: 2|M| / (J_source + J_target), as a fraction.
    pub fn rate(pairs: usize, source_joints: usize, target_joints: usize) -> f64 {
        if source_joints + target_joints == 0 {
            return 0.0;
        }
        2.0 * pairs as f64 / (source_joints + target_joints) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::chain;

    #[test]
    fn reads_the_reference_format_and_resolves_by_normalised_name() {
        let text = r#"{"source_name": "Flamingo", "root_joint": "Hips",
            "mapping": [{"source": "Bip01_L_Calf", "target": "LeftLeg"}, {"source": "hips", "target": "mixamorig:Hips"}]}"#;
        let b = Binding::from_json(text, "b.json").unwrap();
        let src = chain(&["Hips", "Bip01_L_Calf"]);
        let tgt = chain(&["mixamorig:Hips", "mixamorig:LeftLeg"]);
        assert_eq!(b.resolve("b.json", &src, "s.bvh", &tgt, "t.bvh").unwrap(), vec![(1, 1), (0, 0)]);
        let again = Binding::from_json(&b.to_json(), "again").unwrap();
        assert_eq!(again.mapping, b.mapping);
        assert_eq!(again.format.as_deref(), Some(FORMAT));
    }

    #[test]
    fn unknown_duplicate_and_empty_are_errors() {
        let src = chain(&["Hips", "Spine"]);
        let tgt = chain(&["Root", "Chest"]);
        let unknown = Binding::from_json(r#"{"mapping": [{"source": "Hip", "target": "Root"}]}"#, "b").unwrap();
        let e = unknown.resolve("b", &src, "s", &tgt, "t").unwrap_err().to_string();
        assert!(e.contains("pair 0: source joint: s: no joint named 'Hip' (closest: Hips"), "{e}");
        let dup = Binding::from_json(r#"{"mapping": [{"source": "Hips", "target": "Root"}, {"source": "Spine", "target": "Root"}]}"#, "b").unwrap();
        let e = dup.resolve("b", &src, "s", &tgt, "t").unwrap_err().to_string();
        assert!(e.contains("pairs 0 and 1 both bind target joint 'Root'"), "{e}");
        assert!(matches!(Binding::from_json(r#"{"mapping": []}"#, "b"), Err(BindingError::Empty { .. })));
        assert!(matches!(Binding::from_json("[1, 2]", "b"), Err(BindingError::Parse { .. })));
    }
}
