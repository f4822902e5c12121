//! Joint names: renamed from a map, or normalised.
//!
//! Rigs from different tools name one bone `mixamorig:LeftUpLeg`, `Bip01_L_Thigh` and
//! `thigh.L`; game engines and retargeting setups want their own names. A map says old -> new
//! for some joints; `--normalise` uses the readable names `skel-info` prints
//! (`names::readable`, ordinals kept: `leg_l1_coxa` -> `LeftLeg1Coxa`), written without spaces
//! so every tool takes them, made unique with a number where two joints still read the same.

use super::EditError;
use crate::skeleton::{lookup, names, Skeleton};
use std::collections::{BTreeMap, BTreeSet};

/// Pairs old -> new from the map file at `path` (`-` = stdin): `parse_map`, errors naming it.
pub fn read_map(path: &std::path::Path) -> Result<Vec<(String, String)>, EditError> {
    let name = crate::io::display_name(path);
    let text = crate::io::read_input(path).map_err(|e| EditError::Invalid(format!("cannot read {name}: {e}")))?;
    parse_map(&String::from_utf8_lossy(&text)).map_err(|e| EditError::Invalid(format!("{name}: {e}")))
}

/// Pairs old -> new from a map file: a JSON object `{"old": "new"}`, or lines `old new`
/// (a tab separates names that hold spaces; blank lines and `#` comments are skipped).
pub fn parse_map(text: &str) -> Result<Vec<(String, String)>, EditError> {
    if text.trim_start().starts_with('{') {
        let map: serde_json::Map<String, serde_json::Value> =
            serde_json::from_str(text).map_err(|e| EditError::Invalid(format!("not a JSON object of names: {e}")))?;
        return map
            .into_iter()
            .map(|(k, v)| match v {
                serde_json::Value::String(s) => Ok((k, s)),
                other => Err(EditError::Invalid(format!("'{k}' maps to {other}, expected a name in quotes"))),
            })
            .collect();
    }
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = if line.contains('\t') { line.split('\t').map(str::trim).collect() } else { line.split_whitespace().collect() };
        match fields.as_slice() {
            [old, new] if !old.is_empty() && !new.is_empty() => out.push((old.to_string(), new.to_string())),
            _ => return Err(EditError::Invalid(format!("line {}: expected 'old new' (a tab between names with spaces), found '{line}'", i + 1))),
        }
    }
    Ok(out)
}

/// The skeleton with the map's names. Every old name must name one joint (as `--joint` names
/// do everywhere: exactly, else ignoring case or namespace, else by normalised name); the new
/// names must be
/// unique, non-empty and without line breaks or braces (a BVH could not hold them).
pub fn rename(skeleton: &Skeleton, map: &[(String, String)]) -> Result<Skeleton, EditError> {
    let mut s = skeleton.clone();
    let mut seen = BTreeSet::new();
    for (old, new) in map {
        if !seen.insert(old) {
            return Err(EditError::Invalid(format!("'{old}' is renamed twice")));
        }
        let j = lookup::find_joint(skeleton, old).map_err(|e| EditError::Invalid(e.to_string()))?;
        s.joints[j].name = new.clone();
    }
    check_names(&s)?;
    Ok(s)
}

/// The skeleton with `names::readable` names, spaces dropped, duplicates numbered in joint
/// order (`LeftLeg`, `LeftLeg2`, ...). Not `names::normalise`: it drops ordinals, so `Spine`,
/// `Spine1`, `Spine2` would all read `Spine` and be renumbered out of step with their names.
pub fn normalise(skeleton: &Skeleton) -> Result<Skeleton, EditError> {
    let mut s = skeleton.clone();
    let base: Vec<String> = skeleton.joints.iter().map(|j| names::readable(&j.name).split_whitespace().collect::<String>()).collect();
    let mut count: BTreeMap<&str, usize> = BTreeMap::new();
    for b in &base {
        *count.entry(b.as_str()).or_default() += 1;
    }
    let mut used: BTreeSet<String> = BTreeSet::new();
    let mut next: BTreeMap<&str, usize> = BTreeMap::new();
    for (j, b) in base.iter().enumerate() {
        let b = if b.is_empty() { "Joint" } else { b.as_str() };
        let mut name = b.to_string();
        if count.get(b).copied().unwrap_or(0) > 1 || used.contains(&name) {
            loop {
                let k = next.entry(b).or_insert(1);
                name = format!("{b}{k}");
                *k += 1;
                if !used.contains(&name) && !base.contains(&name) {
                    break;
                }
            }
        }
        used.insert(name.clone());
        s.joints[j].name = name;
    }
    check_names(&s)?;
    Ok(s)
}

fn check_names(s: &Skeleton) -> Result<(), EditError> {
    let mut seen = BTreeSet::new();
    for (j, joint) in s.joints.iter().enumerate() {
        let n = &joint.name;
        if n.trim().is_empty() || n.contains(['\n', '\r', '{', '}']) {
            return Err(EditError::Invalid(format!("joint {j}: '{}' cannot be a joint name (empty, a line break or a brace)", n.escape_default())));
        }
        if !seen.insert(n.as_str()) {
            return Err(EditError::Invalid(format!("two joints would be named '{n}'")));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::tests::creature;
    use super::*;

    #[test]
    fn maps_in_both_spellings_rename_and_bad_ones_say_why() {
        let (s, _) = creature();
        let first = s.joints[0].name.clone();
        let second = s.joints[1].name.clone();
        let json = format!("{{\"{first}\": \"Hips\"}}");
        assert_eq!(rename(&s, &parse_map(&json).unwrap()).unwrap().joints[0].name, "Hips");
        let lines = format!("# comment\n{first} Hips\n\n{second}\tSpine Base\n");
        let r = rename(&s, &parse_map(&lines).unwrap()).unwrap();
        assert_eq!((r.joints[0].name.as_str(), r.joints[1].name.as_str()), ("Hips", "Spine Base"));
        assert!(parse_map("a b c\n").unwrap_err().to_string().contains("line 1"));
        assert!(rename(&s, &[("nope".into(), "x".into())]).is_err());
        assert!(rename(&s, &[(first, second)]).unwrap_err().to_string().contains("two joints"));
    }

    #[test]
    fn normalised_names_are_unique_and_readable() {
        let (s, _) = creature();
        let n = normalise(&s).unwrap();
        assert!(n.joints.iter().all(|j| !j.name.contains(' ')));
        let twice = normalise(&n).unwrap();
        assert_eq!(twice.len(), n.len());
    }
}
