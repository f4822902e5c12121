//! The skeleton document as text for people (`skel-info --format text`): the joint tree with
//! offsets, sides and roles, then the summary numbers, so that a skeleton can be read at a
//! glance without a JSON viewer.

use super::SkeletonDocument;
use crate::skeleton::names::Side;
use std::fmt::Write as _;

impl SkeletonDocument {
    /// A readable tree and summary of the document (`skel-info --format text`).
    pub fn text_report(&self) -> String {
        let doc = self;
        let mut s = String::new();
        let _ = writeln!(s, "{}", doc.source);
        let children = {
            let mut c = vec![Vec::new(); doc.joints.len()];
            for (j, e) in doc.joints.iter().enumerate() {
                if let Some(p) = e.parent {
                    c[p].push(j);
                }
            }
            c
        };
        let name_width = doc.joints.iter().map(|e| e.name.chars().count() + 2 * e.depth).max().unwrap_or(0).min(60);
        let norm_width = doc.joints.iter().map(|e| e.normalised.chars().count()).max().unwrap_or(0).min(40);
        // Depth-first with explicit stack; tree glyphs from each ancestor's "is last child" state.
        let mut stack: Vec<(usize, Vec<bool>)> = vec![(0, Vec::new())];
        while let Some((j, lasts)) = stack.pop() {
            let e = &doc.joints[j];
            let mut prefix = String::new();
            for (k, &last) in lasts.iter().enumerate() {
                prefix.push_str(if k + 1 == lasts.len() {
                    if last {
                        "└─"
                    } else {
                        "├─"
                    }
                } else if last {
                    "  "
                } else {
                    "│ "
                });
            }
            let label = format!("{prefix}{}", e.name);
            let pad = name_width.saturating_sub(label.chars().count());
            let side = match e.side {
                Side::Left => "L",
                Side::Right => "R",
                Side::Centre => "·",
            };
            let mut marks = String::new();
            if e.foot {
                marks.push_str(" foot");
            }
            if e.end_effector {
                marks.push_str(" end");
            }
            let _ = writeln!(
                s,
                "  {label}{:pad$}  {:<norm_width$}  {side}  [{:>8.3} {:>8.3} {:>8.3}]  {}ch{marks}",
                "",
                e.normalised,
                e.offset[0],
                e.offset[1],
                e.offset[2],
                e.channels.len(),
            );
            let kids = &children[j];
            for (k, &c) in kids.iter().enumerate().rev() {
                let mut l = lasts.clone();
                l.push(k + 1 == kids.len());
                stack.push((c, l));
            }
        }
        let t = &doc.topology;
        let names = |idx: &[usize]| idx.iter().map(|&j| doc.joints[j].name.as_str()).collect::<Vec<_>>().join(", ");
        let _ = writeln!(
            s,
            "  joints: {}   chains: {}   end effectors: {}   max depth: {}",
            doc.joint_count,
            t.chains.len(),
            t.end_effectors.len(),
            doc.joints.iter().map(|e| e.depth).max().unwrap_or(0)
        );
        let _ = writeln!(s, "  feet ({:?}): {}", t.foot_rule, if t.feet.is_empty() { "none".into() } else { names(&t.feet) });
        let sides = |side: Side| doc.joints.iter().filter(|e| e.side == side).count();
        let _ = writeln!(s, "  sides: {} left, {} right, {} centre", sides(Side::Left), sides(Side::Right), sides(Side::Centre));
        let r = &doc.rest_pose;
        let _ = write!(s, "  rest pose: height {:.4}, extent {:.4}", r.height, r.extent);
        if let Some(b) = &r.bone_length {
            let _ = write!(s, ", bone length {:.4}..{:.4} (mean {:.4})", b.min, b.max, b.mean);
        }
        s.push('\n');
        if let Some(a) = &doc.anytop {
            let rig = &a.rig;
            let facing = match &rig.facing {
                crate::repr::anytop::Facing::FaceJoints(f) => format!("face joints {}", names(f)),
                crate::repr::anytop::Facing::BodyAxis { front, back } => {
                    format!("body axis {} -> {}", doc.joints[*back].name, doc.joints[*front].name)
                }
            };
            let _ = writeln!(
                s,
                "  anytop: scale {:.5}, {facing}, {} contact joints, statistics {}",
                rig.scale_factor,
                rig.feet.len(),
                if a.stats.is_some() { "yes" } else { "no" }
            );
        }
        match &doc.motion {
            Some(m) => {
                let _ = writeln!(s, "  motion: {} frames at {:.3} fps ({:.2} s)", m.frames, m.fps, m.duration_s);
            }
            None => {
                let _ = writeln!(s, "  motion: none (frame time {})", doc.frame_time);
            }
        }
        s
    }
}
