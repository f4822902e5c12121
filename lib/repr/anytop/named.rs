//! Rig overrides given by joint name (face joints, body axis, feet), resolved on a skeleton.
//!
//! People name joints, the rig wants indices; the names are matched as `skeleton::lookup`
//! matches them everywhere else, and each message says which override (`--face-joints`, ...)
//! and which file the name was looked up in, since that is what the user typed.

use super::{RestSource, RigOptions};
use crate::skeleton::{lookup, Skeleton};

/// The overrides by joint name; `None` leaves the automatic choice.
#[derive(Clone, Debug, Default)]
pub struct NamedOverrides {
    /// R_HIP, L_HIP, R_SHOULDER, L_SHOULDER.
    pub face_joints: Option<Vec<String>>,
    /// FRONT, BACK.
    pub body_axis: Option<Vec<String>>,
    pub feet: Option<Vec<String>>,
}

impl NamedOverrides {
    /// The first override given, by its flag, for messages that refuse them all.
    pub fn first_given(&self) -> Option<&'static str> {
        [(self.face_joints.is_some(), "--face-joints"), (self.body_axis.is_some(), "--body-axis"), (self.feet.is_some(), "--feet")]
            .into_iter()
            .find_map(|(on, flag)| on.then_some(flag))
    }

    /// The overrides as rig options, names resolved on `skeleton` (read from `file`).
    pub fn resolve(&self, skeleton: &Skeleton, file: &str, rest_source: RestSource) -> Result<RigOptions, String> {
        let mut options = RigOptions { rest_source, ..RigOptions::default() };
        if let Some(names) = &self.face_joints {
            let j = joint_indices("--face-joints", names, skeleton, file)?;
            let Ok(four) = <[usize; 4]>::try_from(j) else {
                return Err(format!("--face-joints takes four joint names, R_HIP,L_HIP,R_SHOULDER,L_SHOULDER; got {}", names.len()));
            };
            if four[0] == four[1] || four[2] == four[3] {
                return Err("--face-joints: the right and left joint of a pair must differ (R_HIP,L_HIP,R_SHOULDER,L_SHOULDER)".to_string());
            }
            options.face_joints = Some(four);
        }
        if let Some(names) = &self.body_axis {
            let j = joint_indices("--body-axis", names, skeleton, file)?;
            let Ok([front, back]) = <[usize; 2]>::try_from(j) else {
                return Err(format!("--body-axis takes two joint names, FRONT,BACK; got {}", names.len()));
            };
            if front == back {
                return Err("--body-axis: FRONT and BACK must be different joints".to_string());
            }
            options.body_axis = Some([front, back]);
        }
        if let Some(names) = &self.feet {
            options.feet = Some(joint_indices("--feet", names, skeleton, file)?);
        }
        Ok(options)
    }
}

/// Joint indices of names given for `flag` (`skeleton::lookup::find_joint`).
fn joint_indices(flag: &str, names: &[String], skeleton: &Skeleton, file: &str) -> Result<Vec<usize>, String> {
    if names.iter().all(|n| n.trim().is_empty()) {
        return Err(format!("{flag} needs joint names, separated by commas"));
    }
    names
        .iter()
        .map(|raw| match lookup::find_joint(skeleton, raw) {
            Ok(j) => Ok(j),
            Err(lookup::LookupError::Empty) => Err(format!("{flag}: an empty joint name in '{}'", names.join(","))),
            Err(e) => Err(format!("{flag}: {file}: {e}")),
        })
        .collect()
}
