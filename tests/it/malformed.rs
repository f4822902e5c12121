//! Malformed BVH input: every case exits 2 with one line on stderr that names the file and the
//! line where the problem is, and says what was expected. No panics, no output.
use crate::common;

/// A valid two-joint file, line by line, that the cases below break in one place each.
const GOOD: &[&str] = &[
    "HIERARCHY",                                                                // 1
    "ROOT Hips",                                                                // 2
    "{",                                                                        // 3
    "\tOFFSET 0 1 0",                                                           // 4
    "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation", // 5
    "\tJOINT Spine",                                                            // 6
    "\t{",                                                                      // 7
    "\t\tOFFSET 0 0.2 0",                                                       // 8
    "\t\tCHANNELS 3 Zrotation Xrotation Yrotation",                             // 9
    "\t\tEnd Site",                                                             // 10
    "\t\t{",                                                                    // 11
    "\t\t\tOFFSET 0 0.3 0",                                                     // 12
    "\t\t}",                                                                    // 13
    "\t}",                                                                      // 14
    "}",                                                                        // 15
    "MOTION",                                                                   // 16
    "Frames: 2",                                                                // 17
    "Frame Time: 0.0333333",                                                    // 18
    "0 1 0 0 0 0 1 2 3",                                                        // 19
    "0 1 0.1 0 0 0 4 5 6",                                                      // 20
];

fn with(line: usize, replacement: &str) -> String {
    let mut lines: Vec<String> = GOOD.iter().map(|s| s.to_string()).collect();
    lines[line - 1] = replacement.to_string();
    lines.join("\n") + "\n"
}

fn without_lines(from: usize, to: usize) -> String {
    let lines: Vec<&str> = GOOD.iter().enumerate().filter(|(i, _)| *i + 1 < from || *i + 1 > to).map(|(_, s)| *s).collect();
    lines.join("\n") + "\n"
}

fn good() -> String {
    GOOD.join("\n") + "\n"
}

#[test]
fn the_base_file_is_valid() {
    let out = common::run("skel-info", &["-"], Some(good().as_bytes()));
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn malformed_inputs_exit_2_with_file_and_line() {
    // (name, input, expected line, a word the message must contain)
    let cases: Vec<(&str, String, usize, &str)> = vec![
        ("empty file", String::new(), 1, "HIERARCHY"),
        ("not a bvh", "hello world\n".into(), 1, "HIERARCHY"),
        ("missing ROOT", with(2, "JOINT Hips"), 2, "ROOT"),
        ("root without name", with(2, "ROOT"), 2, "name"),
        ("missing open brace", with(3, "OFFSET 0 1 0"), 3, "{"),
        ("non-numeric offset", with(4, "\tOFFSET 0 abc 0"), 4, "number"),
        ("NaN offset", with(4, "\tOFFSET 0 nan 0"), 4, "finite"),
        ("inf offset", with(4, "\tOFFSET inf 1 0"), 4, "finite"),
        ("short offset", with(4, "\tOFFSET 0 1"), 5, "number"),
        ("channel count too big", with(5, "\tCHANNELS 9 Xposition Yposition Zposition Zrotation Xrotation Yrotation"), 5, "channel count"),
        ("negative channel count", with(5, "\tCHANNELS -3 Xrotation Yrotation Zrotation"), 5, "channel count"),
        ("unknown channel", with(9, "\t\tCHANNELS 3 Zrotation Wrotation Yrotation"), 9, "channel name"),
        ("repeated channel", with(9, "\t\tCHANNELS 3 Zrotation Zrotation Yrotation"), 9, "twice"),
        ("unknown keyword", with(8, "\t\tOFSET 0 0.2 0"), 8, "expected"),
        ("End without Site", with(10, "\t\tEnd"), 11, "Site"),
        ("End Site without offset", with(12, "\t\t\tCHANNELS 0"), 12, "OFFSET"),
        ("duplicate joint name", with(6, "\tJOINT Hips"), 6, "duplicate"),
        ("missing offset", with(8, ""), 14, "OFFSET"),
        ("unbalanced: missing close brace", without_lines(15, 15), 15, "unbalanced"),
        ("unbalanced: extra close brace", with(16, "}\nMOTION"), 16, "unbalanced"),
        ("missing MOTION", without_lines(16, 20), 15, "MOTION"),
        ("missing Frames", with(17, "Framez: 2"), 17, "Frames"),
        ("negative frame count", with(17, "Frames: -2"), 17, "frame count"),
        ("non-integer frame count", with(17, "Frames: 2.5"), 17, "frame count"),
        ("absurd frame count", with(17, "Frames: 99999999999999"), 20, "announced 99999999999999"),
        ("overflowing frame count", with(17, "Frames: 99999999999999999999999"), 17, "frame count"),
        ("frame count beyond memory", with(17, "Frames: 18446744073709551615"), 17, "absurd"),
        ("zero frame time", with(18, "Frame Time: 0"), 18, "frame time"),
        ("negative frame time", with(18, "Frame Time: -0.03"), 18, "frame time"),
        ("missing frame time", with(18, "Frame Time:"), 19, "frame time"),
        ("too few values in a row", with(19, "0 1 0 0 0 0 1 2"), 19, "expected 9"),
        ("too many values in a row", with(20, "0 1 0.1 0 0 0 4 5 6 7"), 20, "more than"),
        ("non-numeric value", with(20, "0 1 0.1 0 0 0 4 x 6"), 20, "Xrotation"),
        ("NaN value", with(19, "0 1 0 0 0 nan 1 2 3"), 19, "finite"),
        ("infinite value", with(19, "0 1 0 0 0 0 1 2 -inf"), 19, "finite"),
        ("too few frame rows", without_lines(20, 20), 19, "announced 2"),
        ("too many frame rows", good() + "1 1 1 1 1 1 1 1 1\n", 21, "more frame rows"),
        ("truncated mid-hierarchy", GOOD[..9].join("\n"), 9, "end of file"),
        ("truncated mid-row", good()[..good().len() - 8].to_string(), 20, "expected 9"),
        ("second ROOT", with(16, "ROOT Other\n{\nOFFSET 0 0 0\n}\nMOTION"), 16, "ROOT"),
    ];
    assert!(cases.len() >= 25);
    let dir = std::env::temp_dir().join(format!("menagerie-malformed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut failures = Vec::new();
    for (i, (name, input, line, word)) in cases.iter().enumerate() {
        let file = dir.join(format!("case{i:02}.bvh"));
        std::fs::write(&file, input).unwrap();
        let target = dir.join(format!("case{i:02}.json"));
        let out = common::run("skel-info", &[file.to_str().unwrap(), "-o", target.to_str().unwrap()], None);
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        let want_loc = format!("{}:{line}:", file.display());
        let ok = out.status.code() == Some(2)
            && err.trim_end().lines().count() == 1
            && err.starts_with("skel-info: ")
            && err.contains(&want_loc)
            && err.contains(word)
            && !target.exists()
            && out.stdout.is_empty();
        if !ok {
            failures.push(format!("{name}: exit {:?}, want '{want_loc}' and '{word}', got: {err}", out.status.code()));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failures.is_empty(), "{} of {} cases failed:\n{}", failures.len(), cases.len(), failures.join("\n"));
}

#[test]
fn binary_garbage_never_panics() {
    // Deterministic pseudo-random mutations of the good file: any outcome but a panic is fine.
    let base = good().into_bytes();
    let mut state = 0x9E3779B97F4A7C15u64;
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..300 {
        let mut data = base.clone();
        for _ in 0..(1 + next() % 4) {
            let at = (next() as usize) % data.len();
            match next() % 3 {
                0 => data[at] = next() as u8,
                1 => {
                    data.remove(at);
                }
                _ => data.insert(at, b"{}-.e9 \n#"[(next() % 9) as usize]),
            }
        }
        let result = std::panic::catch_unwind(|| menagerie::bvh::parse_bytes(&data, "mutated"));
        assert!(result.is_ok(), "parser panicked on {:?}", String::from_utf8_lossy(&data));
    }
}
