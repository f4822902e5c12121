//! The BVH reader.
//!
//! The hierarchy is small and irregular, so it goes through a token cursor that knows line
//! numbers; the frame section is large and regular, so it is read row by row straight from the
//! bytes. Nesting uses an explicit stack (no recursion, so deep files cannot overflow the
//! stack), and the header's frame count is checked against the bytes that follow before any
//! frame memory is reserved.

use super::{
    number::{parse_f64, parse_f64_prefix},
    Bvh, BvhError, BvhJoint, Channel,
};
use std::collections::HashMap;
use std::path::Path;

/// Most channels a joint may declare. Six covers position + rotation; anything more is a
/// different format (scale channels, corrupt counts) and is refused rather than guessed at.
const MAX_CHANNELS_PER_JOINT: usize = 6;

/// Read and parse a BVH file. `-` reads standard input.
pub fn read_path(path: &Path) -> Result<Bvh, BvhError> {
    let name = crate::io::display_name(path);
    let data = crate::io::read_input(path).map_err(|source| BvhError::Io { file: name.clone(), source })?;
    parse_bytes(&data, &name)
}

/// Parse BVH text. `file` is only used in error messages.
pub fn parse(text: &str, file: &str) -> Result<Bvh, BvhError> {
    parse_bytes(text.as_bytes(), file)
}

/// Parse BVH bytes (UTF-8 or Latin-1 names are both accepted; names are decoded lossily).
pub fn parse_bytes(data: &[u8], file: &str) -> Result<Bvh, BvhError> {
    let data = data.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(data);
    let mut cur = Cursor { data, pos: 0, line: 1, last_line: 1, file };
    let joints = parse_hierarchy(&mut cur)?;
    let (frames, frame_time) = parse_motion_header(&mut cur)?;
    let channels: usize = joints.iter().map(|j| j.channels.len()).sum();
    let values = parse_frames(&mut cur, &joints, frames, channels)?;
    Ok(Bvh { joints, frame_time, frames, values })
}

struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
    /// Line of the last token returned: end-of-file errors point here, at the last line with
    /// content, rather than at the empty line after a final newline.
    last_line: usize,
    file: &'a str,
}

fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | b'\n' | 0x0B | 0x0C)
}

/// `s` without trailing `is_space` bytes. (`<[u8]>::trim_ascii_end` is not the same: it keeps
/// 0x0B, which `is_space` and so the tokenizer treat as whitespace.)
fn trim_space_end(mut s: &[u8]) -> &[u8] {
    while let [rest @ .., last] = s {
        if is_space(*last) {
            s = rest
        } else {
            break;
        }
    }
    s
}

fn show(tok: &[u8]) -> String {
    let s = String::from_utf8_lossy(tok);
    if s.chars().count() > 40 {
        format!("{}...", s.chars().take(40).collect::<String>())
    } else {
        s.into_owned()
    }
}

impl<'a> Cursor<'a> {
    fn err<T>(&self, line: usize, message: impl Into<String>) -> Result<T, BvhError> {
        Err(BvhError::Syntax { file: self.file.to_string(), line, message: message.into() })
    }

    /// Skip whitespace and `#` comments; return the next token and its line, or None at EOF.
    fn next(&mut self) -> Option<(&'a [u8], usize)> {
        let d = self.data;
        loop {
            while self.pos < d.len() && is_space(d[self.pos]) {
                if d[self.pos] == b'\n' {
                    self.line += 1;
                }
                self.pos += 1;
            }
            if self.pos < d.len() && d[self.pos] == b'#' {
                while self.pos < d.len() && d[self.pos] != b'\n' {
                    self.pos += 1;
                }
                continue;
            }
            break;
        }
        if self.pos >= d.len() {
            return None;
        }
        let start = self.pos;
        while self.pos < d.len() && !is_space(d[self.pos]) {
            self.pos += 1;
        }
        self.last_line = self.line;
        Some((&d[start..self.pos], self.line))
    }

    /// The next token, or an error naming what was expected.
    fn expect_any(&mut self, what: &str) -> Result<(&'a [u8], usize), BvhError> {
        match self.next() {
            Some(t) => Ok(t),
            None => self.err(self.last_line, format!("unexpected end of file: expected {what}")),
        }
    }

    fn expect(&mut self, word: &str, what: &str) -> Result<usize, BvhError> {
        let (tok, line) = self.expect_any(what)?;
        if tok.eq_ignore_ascii_case(word.as_bytes()) {
            Ok(line)
        } else {
            self.err(line, format!("expected {what}, found '{}'", show(tok)))
        }
    }

    /// A finite number. `what` names it for error messages and is only called on error: the
    /// description includes the joint name, and building it eagerly for each of many End Sites
    /// under a long-named joint was quadratic (a 2 MB file took a minute to parse).
    fn number(&mut self, what: impl Fn() -> String) -> Result<f64, BvhError> {
        let Some((tok, line)) = self.next() else {
            return self.err(self.last_line, format!("unexpected end of file: expected {}", what()));
        };
        match parse_f64(tok) {
            Some(v) => Ok(v),
            None => self.err(line, format!("expected {} (a finite number), found '{}'", what(), show(tok))),
        }
    }

    /// The rest of the current line, trimmed; used for joint names, which may contain spaces.
    fn rest_of_line(&mut self) -> &'a [u8] {
        let d = self.data;
        let start = self.pos;
        while self.pos < d.len() && d[self.pos] != b'\n' {
            self.pos += 1;
        }
        let mut s = &d[start..self.pos];
        while let [first, rest @ ..] = s {
            if is_space(*first) {
                s = rest
            } else {
                break;
            }
        }
        trim_space_end(s)
    }
}

/// The hierarchy under construction, with the bookkeeping needed for good error messages.
struct Hierarchy {
    joints: Vec<BvhJoint>,
    /// Line of each joint's ROOT/JOINT keyword.
    lines: Vec<usize>,
    has_offset: Vec<bool>,
    by_name: HashMap<String, usize>,
    /// Open joints, innermost last.
    stack: Vec<usize>,
}

impl Hierarchy {
    /// After a ROOT/JOINT keyword: read the name and the opening brace.
    fn open_joint(&mut self, cur: &mut Cursor, parent: Option<usize>, line: usize) -> Result<(), BvhError> {
        let raw = cur.rest_of_line();
        // Accept `JOINT name {` on one line.
        // Trim with `is_space`, the set `rest_of_line` trims, not `trim_ascii_end`, which keeps
        // a vertical tab: `ROOT r\x0B{` would name the joint "r\x0B", the writer's `ROOT r\x0B`
        // would read back as "r", and the round trip would change the name (found by fuzzing).
        let (raw, brace_inline) = match raw.strip_suffix(b"{") {
            Some(r) => (trim_space_end(r), true),
            None => (raw, false),
        };
        if raw.is_empty() {
            return cur.err(line, "expected a joint name after ROOT/JOINT");
        }
        let name = String::from_utf8_lossy(raw).into_owned();
        if let Some(&first) = self.by_name.get(&name) {
            return cur.err(line, format!("duplicate joint name '{name}' (first defined at line {})", self.lines[first]));
        }
        if !brace_inline {
            cur.expect("{", &format!("'{{' opening joint '{name}'"))?;
        }
        self.by_name.insert(name.clone(), self.joints.len());
        self.lines.push(line);
        self.has_offset.push(false);
        self.stack.push(self.joints.len());
        self.joints.push(BvhJoint { name, parent, offset: [0.0; 3], channels: Vec::new(), end_sites: Vec::new() });
        Ok(())
    }

    /// Three numbers; `what` describes them, lazily (see `Cursor::number`).
    fn offset(cur: &mut Cursor, what: impl Fn() -> String) -> Result<[f64; 3], BvhError> {
        let mut o = [0.0; 3];
        for (k, v) in o.iter_mut().enumerate() {
            *v = cur.number(|| format!("{} {}", what(), ["x", "y", "z"][k]))?;
        }
        Ok(o)
    }

    fn channels(&mut self, cur: &mut Cursor, j: usize, line: usize) -> Result<(), BvhError> {
        if !self.joints[j].channels.is_empty() {
            return cur.err(line, format!("second CHANNELS line for joint '{}'", self.joints[j].name));
        }
        let (ntok, nline) = cur.expect_any("a channel count")?;
        let n = match std::str::from_utf8(ntok).ok().and_then(|s| s.parse::<usize>().ok()) {
            Some(n) if n <= MAX_CHANNELS_PER_JOINT => n,
            _ => return cur.err(nline, format!("expected a channel count from 0 to {MAX_CHANNELS_PER_JOINT}, found '{}'", show(ntok))),
        };
        let mut chans = Vec::with_capacity(n);
        for _ in 0..n {
            let (ctok, cline) = cur.expect_any("a channel name")?;
            match std::str::from_utf8(ctok).ok().and_then(Channel::from_name) {
                Some(c) if !chans.contains(&c) => chans.push(c),
                Some(c) => return cur.err(cline, format!("channel {c} listed twice for joint '{}'", self.joints[j].name)),
                None => return cur.err(cline, format!("expected a channel name (Xposition ... Zrotation), found '{}'", show(ctok))),
            }
        }
        self.joints[j].channels = chans;
        Ok(())
    }
}

fn parse_hierarchy(cur: &mut Cursor) -> Result<Vec<BvhJoint>, BvhError> {
    cur.expect("HIERARCHY", "'HIERARCHY' at the start of the file")?;
    let (tok, line) = cur.expect_any("'ROOT'")?;
    if !tok.eq_ignore_ascii_case(b"ROOT") {
        return cur.err(line, format!("expected 'ROOT', found '{}'", show(tok)));
    }
    let mut h = Hierarchy { joints: Vec::new(), lines: Vec::new(), has_offset: Vec::new(), by_name: HashMap::new(), stack: Vec::new() };
    h.open_joint(cur, None, line)?;
    while let Some(&j) = h.stack.last() {
        let Some((tok, line)) = cur.next() else {
            return cur.err(cur.last_line, format!("unexpected end of file: expected '}}' closing joint '{}'", h.joints[j].name));
        };
        if tok.eq_ignore_ascii_case(b"OFFSET") {
            if h.has_offset[j] {
                return cur.err(line, format!("second OFFSET for joint '{}'", h.joints[j].name));
            }
            h.joints[j].offset = Hierarchy::offset(cur, || format!("OFFSET of joint '{}':", h.joints[j].name))?;
            h.has_offset[j] = true;
        } else if tok.eq_ignore_ascii_case(b"CHANNELS") {
            h.channels(cur, j, line)?;
        } else if tok.eq_ignore_ascii_case(b"JOINT") {
            h.open_joint(cur, Some(j), line)?;
        } else if tok.eq_ignore_ascii_case(b"End") {
            cur.expect("Site", "'Site' after 'End'")?;
            cur.expect("{", "'{' opening End Site")?;
            cur.expect("OFFSET", "OFFSET inside End Site")?;
            let o = Hierarchy::offset(cur, || format!("End Site OFFSET under joint '{}':", h.joints[j].name))?;
            cur.expect("}", "'}' closing End Site")?;
            h.joints[j].end_sites.push(o);
        } else if tok == b"}" {
            if !h.has_offset[j] {
                return cur.err(line, format!("joint '{}' (line {}) has no OFFSET", h.joints[j].name, h.lines[j]));
            }
            h.stack.pop();
        } else if tok.eq_ignore_ascii_case(b"MOTION") {
            return cur.err(line, format!("'MOTION' before joint '{}' was closed: unbalanced braces", h.joints[j].name));
        } else {
            return cur.err(line, format!("expected OFFSET, CHANNELS, JOINT, End Site or '}}', found '{}'", show(tok)));
        }
    }
    Ok(h.joints)
}

fn parse_motion_header(cur: &mut Cursor) -> Result<(usize, f64), BvhError> {
    let Some((tok, line)) = cur.next() else {
        return cur.err(cur.last_line, "unexpected end of file: expected 'MOTION' after the hierarchy");
    };
    if tok.eq_ignore_ascii_case(b"ROOT") {
        return cur.err(line, "a second ROOT: files with several hierarchies are not supported");
    }
    if tok == b"}" {
        return cur.err(line, "unbalanced braces: '}' after the root joint was closed");
    }
    if !tok.eq_ignore_ascii_case(b"MOTION") {
        return cur.err(line, format!("expected 'MOTION' after the hierarchy, found '{}'", show(tok)));
    }
    let (tok, line) = cur.expect_any("'Frames:'")?;
    // Accept both `Frames: 10` and `Frames:10`.
    let count_tok = if tok.eq_ignore_ascii_case(b"Frames:") {
        cur.expect_any("a frame count after 'Frames:'")?
    } else if tok.len() > 7 && tok[..7].eq_ignore_ascii_case(b"Frames:") {
        (&tok[7..], line)
    } else {
        return cur.err(line, format!("expected 'Frames:', found '{}'", show(tok)));
    };
    let frames = match std::str::from_utf8(count_tok.0).ok().and_then(|s| s.parse::<u64>().ok()) {
        Some(n) => n,
        None => return cur.err(count_tok.1, format!("expected a frame count (a non-negative integer), found '{}'", show(count_tok.0))),
    };
    let frames_line = count_tok.1;
    cur.expect("Frame", "'Frame Time:'")?;
    cur.expect("Time:", "'Frame Time:'")?;
    let (ttok, tline) = cur.expect_any("a frame time in seconds")?;
    let frame_time = match parse_f64(ttok) {
        Some(t) if t > 0.0 => t,
        _ => return cur.err(tline, format!("expected a positive frame time in seconds, found '{}'", show(ttok))),
    };
    // The frame rows start on the next line.
    let rest = cur.rest_of_line();
    if !rest.is_empty() {
        return cur.err(tline, format!("unexpected '{}' after the frame time", show(rest)));
    }
    // The count is only trusted as far as the bytes go: memory is reserved for what the rest of
    // the file can hold (see parse_frames), and a count the rows don't back is reported there.
    let frames = usize::try_from(frames).ok().filter(|&f| f <= isize::MAX as usize / 64);
    match frames {
        Some(f) => Ok((f, frame_time)),
        None => cur.err(frames_line, "absurd frame count: more than any file can hold"),
    }
}

fn parse_frames(cur: &mut Cursor, joints: &[BvhJoint], frames: usize, channels: usize) -> Result<Vec<f64>, BvhError> {
    let d = cur.data;
    // Move to the start of the next line (rest_of_line stopped at the newline).
    if cur.pos < d.len() {
        cur.pos += 1;
        cur.line += 1;
    }
    if channels == 0 {
        return Ok(Vec::new());
    }
    // Each value takes at least two bytes (a digit and a separator), so the remaining bytes bound
    // how many values can really follow, whatever the header claims.
    let room = (d.len() - cur.pos.min(d.len())) / 2 + 1;
    let mut values = Vec::with_capacity(frames.saturating_mul(channels).min(room));
    // One pass over the bytes: '\n' ends a row, other whitespace separates values, and each value
    // is parsed where it starts, its end found by the number parser itself. Finding each line,
    // then each token, then parsing it read every byte three times, and the two extra scans were
    // about 40% of the parse time (BENCHMARKS.md). Errors, and the lines they name, are the same
    // as with that line-by-line read.
    let mut row = 0;
    let mut count = 0usize; // values read so far in the current row
    let mut line = cur.line;
    let mut line_start = cur.pos;
    let mut i = cur.pos;
    while i < d.len() {
        let b = d[i];
        if b == b'\n' {
            end_row(cur, line, &mut row, &mut count, channels)?;
            i += 1;
            line += 1;
            line_start = i;
            continue;
        }
        if is_space(b) {
            i += 1;
            continue;
        }
        if row == frames {
            return cur.err(line, format!("more frame rows than 'Frames: {frames}' announced"));
        }
        if count == channels {
            return cur.err(line, format!("frame {} has more than the {channels} values the hierarchy declares", row + 1));
        }
        match parse_f64_prefix(&d[i..]) {
            // A number is only a value if whitespace or the end of the file follows it; `1.5x`
            // parses as far as `1.5` and is then reported whole, like any other bad token.
            Some((v, len)) if d.get(i + len).is_none_or(|&c| is_space(c)) => {
                values.push(v);
                i += len;
            }
            _ => {
                let end = d[i..].iter().position(|&c| is_space(c)).map_or(d.len(), |k| i + k);
                let (joint, chan) = channel_at(joints, count);
                return cur.err(
                    line,
                    format!(
                        "frame {}: expected a finite number for {chan} of joint '{joint}' (value {} of {channels}), found '{}'",
                        row + 1,
                        count + 1,
                        show(&d[i..end])
                    ),
                );
            }
        }
        count += 1;
    }
    // A last line without a final newline.
    if line_start < d.len() {
        end_row(cur, line, &mut row, &mut count, channels)?;
        line += 1;
    }
    if row != frames {
        return cur.err(line.saturating_sub(1).max(1), format!("file ends after {row} frame rows, but 'Frames: {frames}' announced {frames}"));
    }
    Ok(values)
}

/// At the end of a frame-section line: a line with values is a row and must be complete; a blank
/// line is skipped.
fn end_row(cur: &Cursor, line: usize, row: &mut usize, count: &mut usize, channels: usize) -> Result<(), BvhError> {
    if *count != 0 {
        if *count != channels {
            return cur.err(line, format!("frame {} has {count} values, expected {channels} (one per channel)", *row + 1));
        }
        *row += 1;
        *count = 0;
    }
    Ok(())
}

/// Which joint and channel the `k`-th value of a frame row belongs to (for error messages).
fn channel_at(joints: &[BvhJoint], mut k: usize) -> (&str, String) {
    for j in joints {
        if k < j.channels.len() {
            return (&j.name, j.channels[k].to_string());
        }
        k -= j.channels.len();
    }
    ("?", "?".into())
}
