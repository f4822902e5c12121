//! NPY (numpy's `.npy` format) read and write, on any `Read`/`Write`.
//!
//! Motion tensors travel between our tools, and out to Python, as plain `.npy` files (see
//! docs/ARCHITECTURE.md, "Formats between the tools"). The format is small enough to own: a magic
//! string, a version, a Python-literal header dict (`descr`, `fortran_order`, `shape`) padded with
//! spaces to a 64-byte boundary, then the raw values. Owning it means no dependency, no seeking (so
//! pipes work both ways), and errors that say which file and what was found.
//!
//! * The writer emits version 1.0 (2.0 only if a header could not fit in 65535 bytes),
//!   little-endian float32, C order, and lays the header out exactly as `numpy.save` does
//!   (including the spare spaces numpy leaves for growing the first axis), so our files are
//!   byte-identical to numpy's.
//! * The reader accepts versions 1.0, 2.0 and 3.0, `<f4` and `<f8` (converted to f32), C order,
//!   any rank. Everything else (big-endian, integers, objects/pickles, Fortran order) is refused
//!   with the dtype found and the dtype expected. The header is bounded (`MAX_HEADER_BYTES`),
//!   shapes whose element count overflows or disagrees with the data are refused, and data is
//!   read incrementally, so a lying header cannot make us allocate more than the input holds.
//!   No input makes it panic (a seeded mutation test in `tests/it/npy.rs` checks this).

use std::io::{self, Read, Write};

/// `\x93NUMPY`.
pub const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// numpy aligns the data to this many bytes (`numpy.lib.format.ARRAY_ALIGN`).
const ALIGN: usize = 64;

/// numpy leaves room for the first axis to grow to this many digits (`GROWTH_AXIS_MAX_DIGITS`).
const GROWTH_DIGITS: usize = 21;

/// Largest header we read. numpy itself refuses headers over 10000 bytes by default; a header
/// is a short dict, so anything near this bound is garbage or an attack.
pub const MAX_HEADER_BYTES: usize = 65_536;

/// Highest rank we accept (numpy's own limit is 64).
pub const MAX_RANK: usize = 64;

/// An array of float32 values with its shape (C order: the last axis varies fastest).
#[derive(Clone, Debug, PartialEq)]
pub struct NpyArray {
    pub shape: Vec<usize>,
    pub data: Vec<f32>,
}

impl NpyArray {
    /// Number of values the shape holds (1 for a 0-d array).
    pub fn len(&self) -> usize {
        self.data.len()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
}

/// Why an NPY input could not be read. Every variant names the input (`file`).
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    #[error("{file}: {source}")]
    Io {
        file: String,
        #[source]
        source: io::Error,
    },
    #[error("{file}: not an NPY file (found {found}, expected the magic string \\x93NUMPY)")]
    Magic { file: String, found: String },
    #[error("{file}: unsupported NPY format version {major}.{minor} (expected 1.0, 2.0 or 3.0)")]
    Version { file: String, major: u8, minor: u8 },
    #[error("{file}: NPY header of {len} bytes is larger than the {MAX_HEADER_BYTES}-byte limit")]
    HeaderTooLarge { file: String, len: u64 },
    #[error("{file}: truncated NPY header (the input ends after {have} of {want} header bytes)")]
    TruncatedHeader { file: String, have: usize, want: usize },
    #[error("{file}: malformed NPY header: {why} (header: {header})")]
    Header { file: String, why: String, header: String },
    #[error("{file}: unsupported dtype '{found}' (expected '<f4', little-endian float32, or '<f8', little-endian float64)")]
    Dtype { file: String, found: String },
    #[error("{file}: Fortran-ordered arrays are not supported (found fortran_order True, expected False: save with numpy.ascontiguousarray)")]
    FortranOrder { file: String },
    #[error("{file}: shape {shape:?} is too large (rank or element count out of range)")]
    ShapeOverflow { file: String, shape: Vec<usize> },
    #[error("{file}: shape {shape:?} needs {want} data bytes but the input has {have}{more}", more = if *.truncated { "" } else { " or more" })]
    DataLength { file: String, shape: Vec<usize>, want: usize, have: usize, truncated: bool },
}

/// The dtypes we read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Dtype {
    F4,
    F8,
}

impl Dtype {
    fn size(self) -> usize {
        match self {
            Dtype::F4 => 4,
            Dtype::F8 => 8,
        }
    }
}

/// The header text numpy would write for a little-endian float32, C-order array of `shape`
/// (without the padding).
fn header_dict(shape: &[usize]) -> String {
    let dims = match shape {
        [] => "()".to_string(),
        [n] => format!("({n},)"),
        _ => format!("({})", shape.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")),
    };
    let mut h = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {dims}, }}");
    if let Some(first) = shape.first() {
        let digits = first.to_string().len();
        h.extend(std::iter::repeat_n(' ', GROWTH_DIGITS.saturating_sub(digits)));
    }
    h
}

/// The complete NPY header (magic, version, length, padded dict ending in '\n') for `shape`.
pub fn header_bytes(shape: &[usize]) -> Vec<u8> {
    let dict = header_dict(shape);
    // Padded header length when the length field takes `len_bytes` bytes.
    let padded = |len_bytes: usize| {
        let unpadded = MAGIC.len() + 2 + len_bytes + dict.len() + 1;
        dict.len() + (ALIGN - unpadded % ALIGN) % ALIGN + 1
    };
    // Version 1.0 stores the header length in 2 bytes; 2.0 (only when that is too small) in 4.
    let (version, len_bytes) = if padded(2) <= u16::MAX as usize { (1u8, 2) } else { (2u8, 4) };
    let prefix = MAGIC.len() + 2 + len_bytes;
    let header_len = padded(len_bytes);
    let pad = header_len - dict.len() - 1;
    let mut out = Vec::with_capacity(prefix + header_len);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[version, 0]);
    if len_bytes == 2 {
        out.extend_from_slice(&(header_len as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&(header_len as u32).to_le_bytes());
    }
    out.extend_from_slice(dict.as_bytes());
    out.extend(std::iter::repeat_n(b' ', pad));
    out.push(b'\n');
    debug_assert_eq!(out.len() % ALIGN, 0);
    out
}

/// Write `data` (C order) as a little-endian float32 NPY of `shape`.
///
/// Fails with `InvalidInput` when the shape does not hold exactly `data.len()` values.
pub fn write_f32(w: &mut impl Write, shape: &[usize], data: &[f32]) -> io::Result<()> {
    write_f32_parts(w, shape, &[data])
}

/// Like `write_f32`, with the data given as consecutive parts (e.g. the samples of a batch),
/// so a batch is written without first concatenating it.
pub fn write_f32_parts(w: &mut impl Write, shape: &[usize], parts: &[&[f32]]) -> io::Result<()> {
    let count = element_count(shape).ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, format!("shape {shape:?} overflows")))?;
    let given: usize = parts.iter().map(|p| p.len()).sum();
    if count != given {
        return Err(io::Error::new(io::ErrorKind::InvalidInput, format!("shape {shape:?} holds {count} values but {given} were given")));
    }
    w.write_all(&header_bytes(shape))?;
    // Convert in blocks: one large write per block instead of one per value.
    const BLOCK: usize = 16 * 1024;
    let mut buf = Vec::with_capacity(given.min(BLOCK) * 4);
    for chunk in parts.iter().flat_map(|p| p.chunks(BLOCK)) {
        buf.clear();
        for v in chunk {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        w.write_all(&buf)?;
    }
    Ok(())
}

/// The bytes of a little-endian float32 NPY of `shape` holding `data`.
pub fn to_bytes(shape: &[usize], data: &[f32]) -> io::Result<Vec<u8>> {
    let mut out = Vec::with_capacity(ALIGN * 2 + data.len() * 4);
    write_f32(&mut out, shape, data)?;
    Ok(out)
}

/// Product of the dimensions, `None` on overflow or a rank above `MAX_RANK`.
fn element_count(shape: &[usize]) -> Option<usize> {
    if shape.len() > MAX_RANK {
        return None;
    }
    shape.iter().try_fold(1usize, |acc, &d| acc.checked_mul(d))
}

/// Read one NPY array from `r` (to its end: trailing bytes after the data are an error).
/// `file` names the input in errors.
pub fn read(r: &mut impl Read, file: &str) -> Result<NpyArray, NpyError> {
    let io_err = |source: io::Error| NpyError::Io { file: file.to_string(), source };

    let mut lead = [0u8; 8];
    let got = read_up_to(r, &mut lead).map_err(io_err)?;
    if got < 8 || &lead[..6] != MAGIC {
        return Err(NpyError::Magic { file: file.to_string(), found: describe_start(&lead[..got]) });
    }
    let (major, minor) = (lead[6], lead[7]);
    let len_bytes = match (major, minor) {
        (1, 0) => 2,
        (2, 0) | (3, 0) => 4,
        _ => return Err(NpyError::Version { file: file.to_string(), major, minor }),
    };
    let mut len_buf = [0u8; 4];
    let got = read_up_to(r, &mut len_buf[..len_bytes]).map_err(io_err)?;
    if got < len_bytes {
        return Err(NpyError::TruncatedHeader { file: file.to_string(), have: 8 + got, want: 8 + len_bytes });
    }
    let header_len = if len_bytes == 2 { u16::from_le_bytes([len_buf[0], len_buf[1]]) as u64 } else { u32::from_le_bytes(len_buf) as u64 };
    if header_len > MAX_HEADER_BYTES as u64 {
        return Err(NpyError::HeaderTooLarge { file: file.to_string(), len: header_len });
    }
    let header_len = header_len as usize;
    let mut header = vec![0u8; header_len];
    let got = read_up_to(r, &mut header).map_err(io_err)?;
    if got < header_len {
        return Err(NpyError::TruncatedHeader { file: file.to_string(), have: got, want: header_len });
    }
    // Versions 1 and 2 are latin-1, 3 is UTF-8; the dict we accept is ASCII either way, so
    // anything else shows up as a parse error naming the odd text.
    let text = String::from_utf8_lossy(&header);
    let parsed = parse_header(&text).map_err(|why| NpyError::Header { file: file.to_string(), why, header: shorten(text.trim_end()) })?;
    let dtype = match parsed.descr.as_str() {
        "<f4" => Dtype::F4,
        "<f8" => Dtype::F8,
        other => return Err(NpyError::Dtype { file: file.to_string(), found: shorten(other) }),
    };
    if parsed.fortran_order {
        return Err(NpyError::FortranOrder { file: file.to_string() });
    }
    let shape = parsed.shape;
    let overflow = || NpyError::ShapeOverflow { file: file.to_string(), shape: shape.clone() };
    let count = element_count(&shape).ok_or_else(overflow)?;
    let want = count.checked_mul(dtype.size()).ok_or_else(overflow)?;

    // Read at most want + 1 bytes, growing as data arrives: a header claiming terabytes over a
    // short pipe costs only what the pipe holds.
    let mut bytes = Vec::new();
    r.take(want as u64 + 1).read_to_end(&mut bytes).map_err(io_err)?;
    if bytes.len() != want {
        return Err(NpyError::DataLength { file: file.to_string(), shape, want, have: bytes.len(), truncated: bytes.len() < want });
    }
    let data = match dtype {
        Dtype::F4 => bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect(),
        Dtype::F8 => bytes.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8-byte chunk")) as f32).collect(),
    };
    Ok(NpyArray { shape, data })
}

/// Read one NPY array from bytes in memory.
/// Whether an input is meant as NPY: its magic bytes, or a `.npy` name (so that a damaged NPY
/// is reported as one, not as a BVH missing `HIERARCHY`).
pub fn looks_like_npy(path: &std::path::Path, bytes: &[u8]) -> bool {
    bytes.starts_with(b"\x93NUMPY") || path.extension().is_some_and(|x| x.eq_ignore_ascii_case("npy"))
}

pub fn from_bytes(bytes: &[u8], file: &str) -> Result<NpyArray, NpyError> {
    read(&mut &bytes[..], file)
}

/// Fill `buf` as far as the input allows; returns how many bytes were read.
fn read_up_to(r: &mut impl Read, buf: &mut [u8]) -> io::Result<usize> {
    let mut at = 0;
    while at < buf.len() {
        match r.read(&mut buf[at..]) {
            Ok(0) => break,
            Ok(n) => at += n,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(at)
}

/// What the first bytes of a non-NPY input look like, for the error message.
fn describe_start(bytes: &[u8]) -> String {
    if bytes.is_empty() {
        return "an empty input".to_string();
    }
    let shown: String = bytes.iter().take(8).flat_map(|&b| std::ascii::escape_default(b)).map(char::from).collect();
    let hint = if bytes.starts_with(b"HIERARCH") {
        " (a BVH file?)"
    } else if bytes.trim_ascii_start().starts_with(b"{") {
        " (JSON?)"
    } else {
        ""
    };
    format!("'{shown}'{hint}")
}

/// Header text for a one-line message: control characters escaped, long text cut.
fn shorten(s: &str) -> String {
    const MAX: usize = 120;
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i == MAX {
            out.push_str("...");
            break;
        }
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    out
}

/// The three keys of an NPY header.
#[derive(Debug, PartialEq)]
struct Header {
    descr: String,
    fortran_order: bool,
    shape: Vec<usize>,
}

/// A value in the header dict: the subset of Python literals numpy writes there.
#[derive(Debug, PartialEq)]
enum Literal {
    Str(String),
    Bool(bool),
    Tuple(Vec<usize>),
    /// Anything else (a list descr of a structured dtype, numbers, None): named in errors.
    Other(String),
}

/// Parse `{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3), }` and the variants numpy
/// and other writers produce (any key order, either quote, optional trailing commas, spaces).
fn parse_header(text: &str) -> Result<Header, String> {
    let mut p = Parser { s: text.as_bytes(), at: 0 };
    p.skip_ws();
    p.expect(b'{')?;
    let (mut descr, mut fortran, mut shape) = (None, None, None);
    loop {
        p.skip_ws();
        if p.eat(b'}') {
            break;
        }
        let key = p.string()?;
        p.skip_ws();
        p.expect(b':')?;
        p.skip_ws();
        let value = p.literal()?;
        let slot_taken = |k: &str| format!("key '{k}' appears twice");
        match key.as_str() {
            "descr" => match value {
                Literal::Str(s) => {
                    if descr.replace(s).is_some() {
                        return Err(slot_taken("descr"));
                    }
                }
                Literal::Other(o) => return Err(format!("dtype {o} is a structured dtype (expected '<f4')")),
                v => return Err(format!("'descr' must be a string, found {v:?}")),
            },
            "fortran_order" => match value {
                Literal::Bool(b) => {
                    if fortran.replace(b).is_some() {
                        return Err(slot_taken("fortran_order"));
                    }
                }
                v => return Err(format!("'fortran_order' must be True or False, found {v:?}")),
            },
            "shape" => match value {
                Literal::Tuple(t) => {
                    if shape.replace(t).is_some() {
                        return Err(slot_taken("shape"));
                    }
                }
                v => return Err(format!("'shape' must be a tuple of non-negative integers, found {v:?}")),
            },
            other => return Err(format!("unexpected key '{}'", shorten(other))),
        }
        p.skip_ws();
        if p.eat(b',') {
            continue;
        }
        p.skip_ws();
        p.expect(b'}')?;
        break;
    }
    p.skip_ws();
    if p.at != p.s.len() {
        return Err("text after the closing '}'".to_string());
    }
    Ok(Header {
        descr: descr.ok_or("missing key 'descr'")?,
        fortran_order: fortran.ok_or("missing key 'fortran_order'")?,
        shape: shape.ok_or("missing key 'shape'")?,
    })
}

struct Parser<'a> {
    s: &'a [u8],
    at: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<u8> {
        self.s.get(self.at).copied()
    }

    fn skip_ws(&mut self) {
        while self.peek().is_some_and(|c| c.is_ascii_whitespace()) {
            self.at += 1;
        }
    }

    fn eat(&mut self, c: u8) -> bool {
        if self.peek() == Some(c) {
            self.at += 1;
            true
        } else {
            false
        }
    }

    fn expect(&mut self, c: u8) -> Result<(), String> {
        if self.eat(c) {
            Ok(())
        } else {
            Err(match self.peek() {
                Some(found) => format!("expected '{}' at byte {}, found '{}'", c as char, self.at, std::ascii::escape_default(found)),
                None => format!("expected '{}' at byte {}, found the end of the header", c as char, self.at),
            })
        }
    }

    /// A quoted string without escapes (numpy's keys and simple dtypes never need them).
    fn string(&mut self) -> Result<String, String> {
        let quote = match self.peek() {
            Some(q @ (b'\'' | b'"')) => q,
            _ => return Err(format!("expected a quoted key at byte {}", self.at)),
        };
        self.at += 1;
        let start = self.at;
        while let Some(c) = self.peek() {
            if c == quote {
                let s = String::from_utf8_lossy(&self.s[start..self.at]).into_owned();
                self.at += 1;
                return Ok(s);
            }
            if c == b'\\' {
                return Err("escaped characters in a header string".to_string());
            }
            self.at += 1;
        }
        Err("unterminated string".to_string())
    }

    fn literal(&mut self) -> Result<Literal, String> {
        match self.peek() {
            Some(b'\'' | b'"') => Ok(Literal::Str(self.string()?)),
            Some(b'(') => self.tuple(),
            Some(b'[') => {
                // A structured dtype's descr: a list. Skip it (balanced brackets) to name it.
                let start = self.at;
                let mut depth = 0usize;
                while let Some(c) = self.peek() {
                    self.at += 1;
                    match c {
                        b'[' | b'(' => depth += 1,
                        b']' | b')' => {
                            depth -= 1;
                            if depth == 0 {
                                return Ok(Literal::Other(shorten(&String::from_utf8_lossy(&self.s[start..self.at]))));
                            }
                        }
                        _ => {}
                    }
                }
                Err("unterminated list".to_string())
            }
            _ => {
                let start = self.at;
                while self.peek().is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_' || c == b'.' || c == b'-') {
                    self.at += 1;
                }
                match &self.s[start..self.at] {
                    b"True" => Ok(Literal::Bool(true)),
                    b"False" => Ok(Literal::Bool(false)),
                    b"" => Err(format!("expected a value at byte {}", self.at)),
                    other => Ok(Literal::Other(shorten(&String::from_utf8_lossy(other)))),
                }
            }
        }
    }

    /// `()`, `(5,)`, `(2, 3)`, `(2, 3,)`; Python ints may carry an `L` suffix (Python 2 files).
    fn tuple(&mut self) -> Result<Literal, String> {
        self.expect(b'(')?;
        let mut dims = Vec::new();
        loop {
            self.skip_ws();
            if self.eat(b')') {
                break;
            }
            let start = self.at;
            while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                self.at += 1;
            }
            if self.at == start {
                return Err(format!("expected a non-negative integer in the shape at byte {}", self.at));
            }
            let digits = std::str::from_utf8(&self.s[start..self.at]).expect("ASCII digits");
            let d: usize = digits.parse().map_err(|_| format!("dimension {} is too large", shorten(digits)))?;
            let _ = self.eat(b'L');
            dims.push(d);
            if dims.len() > MAX_RANK {
                return Err(format!("rank above {MAX_RANK}"));
            }
            self.skip_ws();
            if self.eat(b',') {
                continue;
            }
            self.skip_ws();
            self.expect(b')')?;
            break;
        }
        Ok(Literal::Tuple(dims))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_is_numpy_layout_and_aligned() {
        let h = header_bytes(&[2, 3, 4]);
        assert_eq!(h.len(), 128);
        assert_eq!(&h[..8], b"\x93NUMPY\x01\x00");
        assert_eq!(u16::from_le_bytes([h[8], h[9]]) as usize, 118);
        assert!(h.ends_with(b"\n"));
        let text = std::str::from_utf8(&h[10..]).unwrap();
        assert!(text.starts_with("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 4), }"), "{text}");
        for shape in [&[][..], &[5], &[1, 2], &[123456789, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]] {
            assert_eq!(header_bytes(shape).len() % 64, 0, "{shape:?}");
        }
        assert!(String::from_utf8_lossy(&header_bytes(&[5])).contains("'shape': (5,), }"));
        assert!(String::from_utf8_lossy(&header_bytes(&[])).contains("'shape': (), }"));
    }

    #[test]
    fn round_trip_any_rank() {
        for shape in [vec![], vec![0], vec![3], vec![2, 3], vec![2, 0, 4], vec![2, 3, 4, 5]] {
            let n: usize = shape.iter().product();
            let data: Vec<f32> = (0..n).map(|i| i as f32 * 0.5 - 3.0).collect();
            let bytes = to_bytes(&shape, &data).unwrap();
            let back = from_bytes(&bytes, "t.npy").unwrap();
            assert_eq!(back, NpyArray { shape: shape.clone(), data });
        }
    }

    #[test]
    fn writer_refuses_mismatched_data() {
        assert!(to_bytes(&[2, 3], &[0.0; 5]).is_err());
        assert!(to_bytes(&[usize::MAX, 2], &[]).is_err());
    }

    #[test]
    fn header_variants_parse() {
        let h = parse_header("{\"shape\": (3L, 4L), \"fortran_order\": False, \"descr\": \"<f8\"}  \n").unwrap();
        assert_eq!(h, Header { descr: "<f8".into(), fortran_order: false, shape: vec![3, 4] });
        let h = parse_header("{'descr':'<f4','fortran_order':True,'shape':(7,),}").unwrap();
        assert!(h.fortran_order && h.shape == vec![7]);
        for bad in [
            "",
            "{",
            "{'descr': '<f4'}",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2, -3), }",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (99999999999999999999999,), }",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2,), 'extra': 1}",
            "{'descr': '<f4', 'fortran_order': False, 'shape': (2,)} x",
            "{'descr': [('a', '<f4')], 'fortran_order': False, 'shape': (2,)}",
        ] {
            assert!(parse_header(bad).is_err(), "{bad:?} parsed");
        }
    }

    fn with_header(dict: &str, data: &[u8]) -> Vec<u8> {
        let mut out = MAGIC.to_vec();
        out.extend_from_slice(&[1, 0]);
        out.extend_from_slice(&(dict.len() as u16).to_le_bytes());
        out.extend_from_slice(dict.as_bytes());
        out.extend_from_slice(data);
        out
    }

    #[test]
    fn refusals_name_file_and_expectation() {
        let err = |bytes: &[u8]| from_bytes(bytes, "x.npy").unwrap_err().to_string();
        let e = err(&with_header("{'descr': '>f4', 'fortran_order': False, 'shape': (1,), }\n", &[0; 4]));
        assert!(e.starts_with("x.npy: ") && e.contains("'>f4'") && e.contains("'<f4'"), "{e}");
        let e = err(&with_header("{'descr': '<i8', 'fortran_order': False, 'shape': (1,), }\n", &[0; 8]));
        assert!(e.contains("'<i8'"), "{e}");
        let e = err(&with_header("{'descr': '|O', 'fortran_order': False, 'shape': (1,), }\n", &[0; 8]));
        assert!(e.contains("'|O'"), "{e}");
        let e = err(&with_header("{'descr': '<f4', 'fortran_order': True, 'shape': (1,), }\n", &[0; 4]));
        assert!(e.contains("fortran_order True"), "{e}");
        let e = err(&with_header("{'descr': '<f4', 'fortran_order': False, 'shape': (2,), }\n", &[0; 4]));
        assert!(e.contains("needs 8 data bytes but the input has 4"), "{e}");
        let e = err(&with_header("{'descr': '<f4', 'fortran_order': False, 'shape': (1,), }\n", &[0; 12]));
        assert!(e.contains("or more"), "{e}");
        let e = err(&with_header("{'descr': '<f4', 'fortran_order': False, 'shape': (4294967296, 4294967296, 4294967296), }\n", &[]));
        assert!(e.contains("too large"), "{e}");
        let e = err(b"HIERARCHY\nROOT");
        assert!(e.contains("not an NPY file") && e.contains("'HIERARCH' (a BVH file?)"), "{e}");
        let e = err(b"");
        assert!(e.contains("empty input"), "{e}");
        let e = err(b"\x93NUMPY\x04\x00");
        assert!(e.contains("version 4.0"), "{e}");
        let mut big = MAGIC.to_vec();
        big.extend_from_slice(&[2, 0]);
        big.extend_from_slice(&u32::MAX.to_le_bytes());
        assert!(err(&big).contains("limit"));
    }

    #[test]
    fn reads_f8_and_v2_headers() {
        let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (2,), }\n";
        let mut bytes = MAGIC.to_vec();
        bytes.extend_from_slice(&[2, 0]);
        bytes.extend_from_slice(&(dict.len() as u32).to_le_bytes());
        bytes.extend_from_slice(dict.as_bytes());
        bytes.extend_from_slice(&1.5f64.to_le_bytes());
        bytes.extend_from_slice(&(-2.25f64).to_le_bytes());
        let a = from_bytes(&bytes, "v2.npy").unwrap();
        assert_eq!(a, NpyArray { shape: vec![2], data: vec![1.5, -2.25] });
    }
}
