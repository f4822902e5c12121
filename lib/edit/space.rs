//! Edits of space: another axis convention, another size or unit, left and right swapped.
//!
//! Blender works z-up and -y forward, glTF and BVH y-up and +z forward; exporters disagree on
//! metres and centimetres; a clip of a left-handed swing is wanted right-handed. Each of these
//! is one linear map of the world, carried into a skeleton's OFFSETs, translations and local
//! rotations so that forward kinematics gives the mapped world positions.

use super::{check, has_position_channels, EditError};
use crate::bvh::Channel;
use crate::motion::{rotation, Motion};
use crate::skeleton::names::{self, Side};
use crate::skeleton::{roles, Skeleton};
use glam::{DMat3, DQuat, DVec3};
use std::str::FromStr;

/// A coordinate axis with a direction: `x`, `-y`, `+z`; `z-up` also reads as `z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SignedAxis {
    pub axis: usize,
    pub sign: f64,
}

impl SignedAxis {
    pub fn vector(self) -> DVec3 {
        let mut v = DVec3::ZERO;
        v[self.axis] = self.sign;
        v
    }
}

impl FromStr for SignedAxis {
    type Err = String;
    fn from_str(s: &str) -> Result<SignedAxis, String> {
        let t = s.trim().to_ascii_lowercase();
        let t = t.strip_suffix("-up").unwrap_or(&t);
        let (sign, name) = match t.strip_prefix('-') {
            Some(rest) => (-1.0, rest),
            None => (1.0, t.strip_prefix('+').unwrap_or(t)),
        };
        let axis = match name {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return Err(format!("expected an axis such as y-up, z-up, x, -y or +z, found '{s}'")),
        };
        Ok(SignedAxis { axis, sign })
    }
}

/// An axis convention: which way is up and which way a character faces.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Axes {
    pub up: SignedAxis,
    pub forward: SignedAxis,
}

impl Axes {
    /// `up` with the forward axis given, or the usual one for that up: +z for y-up (BVH,
    /// glTF), -y for z-up (Blender), +y for x-up.
    pub fn new(up: SignedAxis, forward: Option<SignedAxis>) -> Result<Axes, EditError> {
        let forward = forward.unwrap_or(match up.axis {
            1 => SignedAxis { axis: 2, sign: 1.0 },
            2 => SignedAxis { axis: 1, sign: -up.sign },
            _ => SignedAxis { axis: 1, sign: 1.0 },
        });
        if forward.axis == up.axis {
            return Err(EditError::Invalid(format!("the forward axis cannot be the up axis ({})", ["x", "y", "z"][up.axis])));
        }
        Ok(Axes { up, forward })
    }

    /// The columns up, forward, up x forward.
    fn basis(self) -> DMat3 {
        let (u, f) = (self.up.vector(), self.forward.vector());
        DMat3::from_cols(u, f, u.cross(f))
    }
}

/// Re-express the rest pose and the motion from the `from` convention in the `to` one: world
/// positions p become R p for the rotation R taking `from`'s up and forward to `to`'s. R only
/// permutes axes and flips signs, so channels are renamed to the axes they map to and the
/// values carry over (a Zrotation of a z-up file becomes the Yrotation of the y-up one).
pub fn axis(skeleton: &Skeleton, motion: &Motion, from: Axes, to: Axes) -> Result<(Skeleton, Motion), EditError> {
    check(skeleton, motion)?;
    let r = to.basis() * from.basis().transpose();
    let q = DQuat::from_mat3(&r).normalize();
    let mut s = skeleton.clone();
    let image = |axis: usize| (0..3).find(|&k| r.col(axis)[k].abs() > 0.5).unwrap_or(axis);
    for joint in &mut s.joints {
        joint.offset = r * joint.offset;
        for e in &mut joint.end_sites {
            *e = r * *e;
        }
        for c in &mut joint.channels {
            *c = channel(image(c.axis()), c.is_rotation());
        }
    }
    let mut m = motion.clone();
    for t in &mut m.translations {
        *t = r * *t;
    }
    for x in &mut m.rotations {
        *x = (q * *x * q.inverse()).normalize();
    }
    Ok((s, m))
}

fn channel(axis: usize, rotation: bool) -> Channel {
    match (axis, rotation) {
        (0, false) => Channel::Xposition,
        (1, false) => Channel::Yposition,
        (2, false) => Channel::Zposition,
        (0, true) => Channel::Xrotation,
        (1, true) => Channel::Yrotation,
        _ => Channel::Zrotation,
    }
}

/// Length units, as metres.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Units {
    M,
    Cm,
    Mm,
    In,
}

impl Units {
    pub fn metres(self) -> f64 {
        match self {
            Units::M => 1.0,
            Units::Cm => 0.01,
            Units::Mm => 0.001,
            Units::In => 0.0254,
        }
    }

    /// A guess from the skeleton's size, for creatures from 20 cm to 20 m: an extent of 20 or
    /// more reads as centimetres, else as metres.
    pub fn guess(skeleton: &Skeleton) -> Units {
        if skeleton.rest_extent() >= 20.0 {
            Units::Cm
        } else {
            Units::M
        }
    }
}

impl FromStr for Units {
    type Err = String;
    fn from_str(s: &str) -> Result<Units, String> {
        match s {
            "m" => Ok(Units::M),
            "cm" => Ok(Units::Cm),
            "mm" => Ok(Units::Mm),
            "in" => Ok(Units::In),
            _ => Err(format!("expected m, cm, mm or in, found '{s}'")),
        }
    }
}

/// Every length times `factor`: OFFSETs, End Sites, translations (root motion included).
pub fn scale(skeleton: &Skeleton, motion: &Motion, factor: f64) -> Result<(Skeleton, Motion), EditError> {
    check(skeleton, motion)?;
    if !(factor.is_finite() && factor > 0.0) {
        return Err(EditError::Invalid(format!("the scale factor must be a positive number, found {factor}")));
    }
    let mut s = skeleton.clone();
    for joint in &mut s.joints {
        joint.offset *= factor;
        for e in &mut joint.end_sites {
            *e *= factor;
        }
    }
    let mut m = motion.clone();
    for t in &mut m.translations {
        *t *= factor;
    }
    Ok((s, m))
}

/// Each joint's mirror partner (itself for centre joints), and the lateral axis (0 = x, 2 = z)
/// left and right lie along. Sides are `skel-info`'s (`roles::sides`); a left joint's partner
/// is the right joint with the same name but for the side words (`names::mirror_key`), else,
/// for joints whose names say nothing, the right joint at the mirrored rest position.
pub fn partners(skeleton: &Skeleton) -> Result<(Vec<usize>, usize), EditError> {
    let normalised: Vec<String> = skeleton.joints.iter().map(|j| names::normalise(&j.name)).collect();
    let sides = roles::sides(skeleton, &normalised);
    let of = |side: Side| (0..skeleton.len()).filter(|&j| sides[j] == side).collect::<Vec<_>>();
    let (lefts, rights) = (of(Side::Left), of(Side::Right));
    if lefts.is_empty() && rights.is_empty() {
        return Err(EditError::Skeleton("no joint has a side (neither the names nor the rest pose say left or right): nothing to mirror".to_string()));
    }
    let pos = skeleton.rest_positions();
    let mean = |js: &[usize]| js.iter().map(|&j| pos[j]).sum::<DVec3>() / js.len().max(1) as f64;
    let across = mean(&lefts) - mean(&rights);
    let lateral = if across.x.abs() >= across.z.abs() { 0 } else { 2 };
    let keys: Vec<String> = skeleton.joints.iter().map(|j| names::mirror_key(&j.name)).collect();
    let depths = skeleton.depths();
    let tolerance = 0.02 * skeleton.rest_extent().max(1e-12);
    let mut partner: Vec<usize> = (0..skeleton.len()).collect();
    let mut taken = vec![false; skeleton.len()];
    for &l in &lefts {
        let by_name: Vec<usize> = rights.iter().copied().filter(|&r| !taken[r] && keys[r] == keys[l]).collect();
        let found = if by_name.len() == 1 {
            Some(by_name[0])
        } else {
            let mut mirrored = pos[l];
            mirrored[lateral] = 2.0 * pos[0][lateral] - mirrored[lateral];
            rights
                .iter()
                .copied()
                .filter(|&r| !taken[r] && depths[r] == depths[l] && pos[r].distance(mirrored) < tolerance)
                .min_by(|&a, &b| pos[a].distance(mirrored).total_cmp(&pos[b].distance(mirrored)))
        };
        let r = found.ok_or_else(|| {
            EditError::Skeleton(format!("left joint {l} '{}' has no right partner (by name or mirrored rest position)", skeleton.joints[l].name))
        })?;
        taken[r] = true;
        partner[l] = r;
        partner[r] = l;
    }
    if let Some(&r) = rights.iter().find(|&&r| !taken[r]) {
        return Err(EditError::Skeleton(format!("right joint {r} '{}' has no left partner (by name or mirrored rest position)", skeleton.joints[r].name)));
    }
    Ok((partner, lateral))
}

/// Left and right swapped: the world reflected across the body's middle plane, and each
/// sided joint given its partner's reflected motion. The skeleton (OFFSETs) is kept, so a rig
/// whose two sides differ keeps its own bones; mirroring twice gives the motion back exactly.
pub fn mirror(skeleton: &Skeleton, motion: &Motion) -> Result<Motion, EditError> {
    check(skeleton, motion)?;
    let (partner, lateral) = partners(skeleton)?;
    let reflect = |mut v: DVec3| {
        v[lateral] = -v[lateral];
        v
    };
    let j = motion.joints;
    let mut out = motion.clone();
    for f in 0..motion.frames {
        for k in 0..j {
            let p = partner[k];
            out.rotations[f * j + k] = rotation::reflect(motion.rotations[f * j + p], lateral);
            if k == 0 || has_position_channels(skeleton, k) {
                out.translations[f * j + k] = reflect(motion.translations[f * j + p]);
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::tests::creature;
    use super::*;

    fn positions(s: &Skeleton, m: &Motion) -> Vec<DVec3> {
        m.forward_kinematics(s).positions
    }

    #[test]
    fn z_up_to_y_up_and_back_is_the_identity() {
        let (s, m) = creature();
        let z: Axes = Axes::new("z-up".parse().unwrap(), None).unwrap();
        let y: Axes = Axes::new("y-up".parse().unwrap(), None).unwrap();
        let (s1, m1) = axis(&s, &m, y, z).unwrap();
        // Blender's convention: y-up +z forward becomes z-up -y forward: (x, y, z) -> (x, -z, y).
        let (p0, p1) = (positions(&s, &m), positions(&s1, &m1));
        for (a, b) in p0.iter().zip(&p1) {
            assert!(b.distance(DVec3::new(a.x, -a.z, a.y)) < 1e-9);
        }
        let (s2, m2) = axis(&s1, &m1, z, y).unwrap();
        assert_eq!(s2.joints.iter().map(|j| &j.channels).collect::<Vec<_>>(), s.joints.iter().map(|j| &j.channels).collect::<Vec<_>>());
        for (a, b) in p0.iter().zip(positions(&s2, &m2)) {
            assert!(a.distance(b) < 1e-9);
        }
        assert!(Axes::new("y".parse().unwrap(), Some("-y".parse().unwrap())).is_err());
    }

    #[test]
    fn scaling_scales_world_positions() {
        let (s, m) = creature();
        let (s2, m2) = scale(&s, &m, 100.0).unwrap();
        for (a, b) in positions(&s, &m).iter().zip(positions(&s2, &m2)) {
            assert!((*a * 100.0).distance(b) < 1e-9);
        }
        assert!(scale(&s, &m, 0.0).is_err());
        assert_eq!(Units::guess(&s2), Units::Cm);
    }

    #[test]
    fn mirroring_twice_is_the_identity_and_once_reflects_the_world() {
        let (s, m) = creature();
        let once = mirror(&s, &m).unwrap();
        assert_eq!(mirror(&s, &once).unwrap(), m);
        let (partner, lateral) = partners(&s).unwrap();
        assert_eq!(lateral, 0);
        let (p, q) = (m.forward_kinematics(&s), once.forward_kinematics(&s));
        for f in [0, m.frames / 2] {
            for k in 0..s.len() {
                let mut want = p.position(f, partner[k]);
                want.x = -want.x;
                assert!(q.position(f, k).distance(want) < 1e-6 * s.rest_extent(), "frame {f} joint {k}");
            }
        }
    }
}
