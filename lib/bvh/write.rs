//! The BVH writer.
//!
//! Numbers are written as the shortest decimal text that parses back to the same f64 (Rust's
//! `Display` for floats), never with a fixed number of decimals: values survive
//! read -> write -> read exactly, and a second write is byte-identical to the first. Layout
//! follows what Blender and MotionBuilder write (tabs, one brace per line, LF endings), so the
//! files import everywhere.

use super::Bvh;
use std::fmt::Write as _;
use std::io::{self, Write};

/// Indentation stops growing past this depth: readers ignore it, and a pathological
/// 20,000-deep chain would otherwise write gigabytes of tabs (quadratic in depth).
const MAX_INDENT: usize = 32;

/// Write `bvh` as BVH text.
pub fn write(bvh: &Bvh, out: &mut impl Write) -> io::Result<()> {
    out.write_all(write_string(bvh).as_bytes())
}

/// BVH text of `bvh`.
pub fn write_string(bvh: &Bvh) -> String {
    let channels = bvh.channel_count();
    // ~10 bytes per value is typical; reserving avoids repeated growth on long clips.
    let mut s = String::with_capacity(4096 + bvh.frames * channels * 11);
    s.push_str("HIERARCHY\n");
    let children = children_of(bvh);
    // Explicit stack of (joint, depth, entering?) so deep hierarchies cannot overflow.
    let mut stack: Vec<(usize, usize, bool)> = (0..bvh.joints.len()).rev().filter(|&j| bvh.joints[j].parent.is_none()).map(|j| (j, 0, true)).collect();
    while let Some((j, depth, entering)) = stack.pop() {
        let joint = &bvh.joints[j];
        let pad = "\t".repeat(depth.min(MAX_INDENT));
        if entering {
            let keyword = if joint.parent.is_none() { "ROOT" } else { "JOINT" };
            if joint.name.ends_with('{') {
                // The reader takes a trailing '{' on the name line as an inline brace, so `JOINT
                // a{ {` names the joint "a{". Such a name must keep its brace on the same line:
                // `JOINT a{` + `{` would read back as "a" plus a stray '{' (found by fuzzing).
                let _ = writeln!(s, "{pad}{keyword} {} {{", joint.name);
            } else {
                let _ = writeln!(s, "{pad}{keyword} {}", joint.name);
                let _ = writeln!(s, "{pad}{{");
            }
            let _ = writeln!(s, "{pad}\tOFFSET {} {} {}", joint.offset[0], joint.offset[1], joint.offset[2]);
            let _ = write!(s, "{pad}\tCHANNELS {}", joint.channels.len());
            for c in &joint.channels {
                let _ = write!(s, " {c}");
            }
            s.push('\n');
            stack.push((j, depth, false));
            for &c in children[j].iter().rev() {
                stack.push((c, depth + 1, true));
            }
        } else {
            for e in &joint.end_sites {
                let _ = writeln!(s, "{pad}\tEnd Site\n{pad}\t{{\n{pad}\t\tOFFSET {} {} {}\n{pad}\t}}", e[0], e[1], e[2]);
            }
            let _ = writeln!(s, "{pad}}}");
        }
    }
    let _ = writeln!(s, "MOTION\nFrames: {}\nFrame Time: {}", bvh.frames, bvh.frame_time);
    if channels > 0 {
        for row in bvh.values.chunks_exact(channels) {
            let mut first = true;
            for v in row {
                if !first {
                    s.push(' ');
                }
                first = false;
                let _ = write!(s, "{v}");
            }
            s.push('\n');
        }
    }
    s
}

fn children_of(bvh: &Bvh) -> Vec<Vec<usize>> {
    let mut children = vec![Vec::new(); bvh.joints.len()];
    for (j, joint) in bvh.joints.iter().enumerate() {
        if let Some(p) = joint.parent {
            children[p].push(j);
        }
    }
    children
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn deep_chains_round_trip_with_bounded_indentation() {
        let depth = 500;
        let mut text = String::from("HIERARCHY\n");
        for k in 0..depth {
            text += &format!("{} j{k}\n{{\nOFFSET 0 1 0\nCHANNELS 1 Zrotation\n", if k == 0 { "ROOT" } else { "JOINT" });
        }
        text += &"}\n".repeat(depth);
        text += "MOTION\nFrames: 1\nFrame Time: 0.5\n";
        text += &vec!["1.5"; depth].join(" ");
        let a = crate::bvh::parse(&text, "deep").unwrap();
        let written = write_string(&a);
        assert!(written.lines().take_while(|l| *l != "MOTION").all(|l| l.len() < MAX_INDENT + 40), "indentation must stay bounded");
        let b = crate::bvh::parse(&written, "deep").unwrap();
        assert_eq!(a, b);
        assert_eq!(write_string(&b), written);
    }
}
