//! Finding a joint by a name a person typed or a file carries: exact first, then looser keys,
//! never by substring (a substring match silently binds `Hand` to `HandThumb1`).

use super::names;
use super::Skeleton;

/// Why a name names no single joint. The message lists what the user could have meant.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LookupError {
    #[error("no joint named '{name}' (closest: {})", closest.join(", "))]
    Unknown { name: String, closest: Vec<String> },
    #[error("'{name}' could be any of {}: give the full name", candidates.join(", "))]
    Ambiguous { name: String, candidates: Vec<String> },
    #[error("an empty joint name")]
    Empty,
}

/// The joint called `name`: its exact name; else the one joint whose name matches ignoring case;
/// else ignoring case and a `namespace:` prefix (Mixamo's `mixamorig:`); else the one joint with
/// the same normalised name (`names::normalise`: `Bip01_L_Foot` = `l_foot` = `LeftFoot`).
/// Each looser key is tried only when the stricter ones found nothing, and a key that fits
/// several joints is an error rather than a guess.
pub fn find_joint(skeleton: &Skeleton, name: &str) -> Result<usize, LookupError> {
    let name = name.trim();
    if name.is_empty() {
        return Err(LookupError::Empty);
    }
    if let Some(j) = skeleton.index_of(name) {
        return Ok(j);
    }
    let lower = |s: &str| s.to_lowercase();
    let bare = |s: &str| s.rsplit(':').next().unwrap_or(s).to_lowercase();
    let normal = |s: &str| names::normalise(s);
    let keys: [&dyn Fn(&str) -> String; 3] = [&lower, &bare, &normal];
    for key in keys {
        let want = key(name);
        if want.is_empty() {
            continue;
        }
        let hits: Vec<usize> = (0..skeleton.len()).filter(|&j| key(&skeleton.joints[j].name) == want).collect();
        match hits[..] {
            [] => {}
            [j] => return Ok(j),
            _ => {
                let candidates = hits.iter().map(|&j| skeleton.joints[j].name.clone()).collect();
                return Err(LookupError::Ambiguous { name: name.to_string(), candidates });
            }
        }
    }
    Err(LookupError::Unknown { name: name.to_string(), closest: closest_names(skeleton, name, 5) })
}

/// Up to `n` joint names nearest to `name` by edit distance (ignoring case and a namespace).
pub fn closest_names(skeleton: &Skeleton, name: &str, n: usize) -> Vec<String> {
    let want: Vec<char> = name.to_lowercase().chars().collect();
    let mut scored: Vec<(usize, usize)> = skeleton
        .joints
        .iter()
        .enumerate()
        .map(|(j, joint)| {
            let full = joint.name.to_lowercase();
            let bare = full.rsplit(':').next().unwrap_or(&full);
            let d = edit_distance(&want, &full.chars().collect::<Vec<_>>()).min(edit_distance(&want, &bare.chars().collect::<Vec<_>>()));
            (d, j)
        })
        .collect();
    scored.sort_unstable();
    scored.iter().take(n).map(|&(_, j)| skeleton.joints[j].name.clone()).collect()
}

fn edit_distance(a: &[char], b: &[char]) -> usize {
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (k, cb) in b.iter().enumerate() {
            let next = (diagonal + usize::from(ca != cb)).min(row[k] + 1).min(row[k + 1] + 1);
            diagonal = row[k + 1];
            row[k + 1] = next;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::chain;

    #[test]
    fn exact_then_case_then_namespace_then_normalised() {
        let s = chain(&["Hips", "mixamorig:LeftUpLeg", "Bip01_L_Foot", "HandThumb1"]);
        assert_eq!(find_joint(&s, "Hips"), Ok(0));
        assert_eq!(find_joint(&s, "hips"), Ok(0));
        assert_eq!(find_joint(&s, "leftupleg"), Ok(1));
        assert_eq!(find_joint(&s, "LeftFoot"), Ok(2));
        assert_eq!(find_joint(&s, "l_foot"), Ok(2));
    }

    #[test]
    fn never_by_substring_and_lists_closest() {
        let s = chain(&["Hips", "HandThumb1", "Spine"]);
        match find_joint(&s, "Hand") {
            Err(LookupError::Unknown { closest, .. }) => assert_eq!(closest[0], "Hips"),
            other => panic!("expected Unknown, got {other:?}"),
        }
        assert_eq!(find_joint(&s, "  "), Err(LookupError::Empty));
    }

    #[test]
    fn ambiguous_keys_are_errors() {
        let s = chain(&["a:Hips", "b:Hips"]);
        assert!(matches!(find_joint(&s, "hips"), Err(LookupError::Ambiguous { .. })));
        assert_eq!(find_joint(&s, "a:Hips"), Ok(0));
    }
}
