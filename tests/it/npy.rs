//! NPY interop and robustness: numpy loads what we write (same bytes as `numpy.save`), we read
//! what numpy writes (float32 and float64, 3-D and 4-D, refusing what we must), reading works
//! through a pipe-like reader that returns a few bytes at a time, and no mutation of a valid
//! file makes the reader panic. The numpy checks print SKIP when python3 + numpy are absent.

use crate::common;
use menagerie::io::npy::{self, NpyArray, NpyError};
use std::io::Read;
use std::path::PathBuf;
use std::process::Command;

fn python_numpy() -> bool {
    Command::new("python3").args(["-c", "import numpy"]).output().is_ok_and(|o| o.status.success())
}

fn python(script: &str) -> String {
    let out = Command::new("python3").arg("-c").arg(script).output().expect("python3");
    assert!(out.status.success(), "python failed: {}\n{script}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

fn tempdir(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("menagerie-npy-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Deterministic values that exercise signs, fractions and magnitudes: i * 0.37 - 5, with a
/// few large and tiny ones.
fn values(n: usize) -> Vec<f32> {
    (0..n)
        .map(|i| match i % 11 {
            3 => 1.0e30 * (i as f32 + 1.0),
            7 => -1.0e-30 / (i as f32 + 1.0),
            _ => i as f32 * 0.37 - 5.0,
        })
        .collect()
}

fn shapes() -> Vec<Vec<usize>> {
    vec![vec![], vec![7], vec![3, 4], vec![5, 4, 9], vec![2, 5, 4, 9], vec![0, 3, 9], vec![1, 1, 1, 1, 1], vec![123, 2, 2]]
}

#[test]
fn numpy_loads_what_we_write_byte_for_byte() {
    if !python_numpy() {
        common::skip("numpy_loads_what_we_write_byte_for_byte", "python3 with numpy is not available");
        return;
    }
    let dir = tempdir("write");
    let mut script = String::from("import numpy as np, io\n");
    for (k, shape) in shapes().iter().enumerate() {
        let n: usize = shape.iter().product();
        let path = dir.join(format!("a{k}.npy"));
        let mut f = std::fs::File::create(&path).unwrap();
        npy::write_f32(&mut f, shape, &values(n)).unwrap();
        let py_shape = match shape.len() {
            0 => "()".to_string(),
            1 => format!("({},)", shape[0]),
            _ => format!("({})", shape.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")),
        };
        // Same values built in numpy, same bytes from numpy.save, same dtype and shape on load.
        script.push_str(&format!(
            "i = np.arange({n}); v = np.where(i % 11 == 3, np.float32(1e30) * (i + 1).astype(np.float32), np.where(i % 11 == 7, np.float32(-1e-30) / (i + 1).astype(np.float32), i.astype(np.float32) * np.float32(0.37) - np.float32(5)))\n\
             want = v.astype(np.float32).reshape({py_shape})\n\
             a = np.load(r'{p}')\n\
             b = io.BytesIO(); np.save(b, want)\n\
             print({k}, a.dtype.str, a.shape == want.shape, a.flags['C_CONTIGUOUS'], bool((a == want).all()), b.getvalue() == open(r'{p}', 'rb').read())\n",
            p = path.display()
        ));
    }
    let out = python(&script);
    for (k, line) in out.lines().enumerate() {
        assert_eq!(line, format!("{k} <f4 True True True True"), "shape {:?}", shapes()[k]);
    }
    assert_eq!(out.lines().count(), shapes().len());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn we_read_what_numpy_writes() {
    if !python_numpy() {
        common::skip("we_read_what_numpy_writes", "python3 with numpy is not available");
        return;
    }
    let dir = tempdir("read");
    let d = dir.display();
    python(&format!(
        "import numpy as np\n\
         a3 = (np.arange(5 * 4 * 9) * 0.37 - 5).reshape(5, 4, 9)\n\
         a4 = (np.arange(2 * 5 * 4 * 9) * -0.125 + 3).reshape(2, 5, 4, 9)\n\
         np.save(r'{d}/f4_3d.npy', a3.astype(np.float32))\n\
         np.save(r'{d}/f8_3d.npy', a3)\n\
         np.save(r'{d}/f4_4d.npy', a4.astype(np.float32))\n\
         np.save(r'{d}/f8_4d.npy', a4)\n\
         np.save(r'{d}/sliced.npy', a4.astype(np.float32)[:, ::2])\n\
         np.save(r'{d}/fortran.npy', np.asfortranarray(a3.astype(np.float32)))\n\
         np.save(r'{d}/big.npy', a3.astype('>f4'))\n\
         np.save(r'{d}/int.npy', np.arange(6, dtype=np.int64).reshape(2, 3))\n\
         np.save(r'{d}/half.npy', a3.astype(np.float16))\n\
         np.save(r'{d}/object.npy', np.array([{{'a': 1}}], dtype=object), allow_pickle=True)\n\
         np.save(r'{d}/structured.npy', np.zeros(3, dtype=[('x', '<f4'), ('y', '<f4')]))\n\
         from numpy.lib import format as fmt\n\
         with open(r'{d}/v2.npy', 'wb') as f:\n\
         \x20   fmt.write_array(f, a3.astype(np.float32), version=(2, 0))\n\
         with open(r'{d}/v3.npy', 'wb') as f:\n\
         \x20   fmt.write_array(f, a3.astype(np.float32), version=(3, 0))\n"
    ));
    let read = |name: &str| {
        let p = dir.join(name);
        npy::read(&mut std::fs::File::open(&p).unwrap(), name)
    };
    let a3: Vec<f32> = (0..180).map(|i| (i as f64 * 0.37 - 5.0) as f32).collect();
    let a4: Vec<f32> = (0..360).map(|i| (i as f64 * -0.125 + 3.0) as f32).collect();
    for (name, shape, data) in [
        ("f4_3d.npy", vec![5, 4, 9], &a3),
        ("f8_3d.npy", vec![5, 4, 9], &a3),
        ("v2.npy", vec![5, 4, 9], &a3),
        ("v3.npy", vec![5, 4, 9], &a3),
        ("f4_4d.npy", vec![2, 5, 4, 9], &a4),
        ("f8_4d.npy", vec![2, 5, 4, 9], &a4),
    ] {
        let got = read(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(got, NpyArray { shape, data: data.clone() }, "{name}");
    }
    // A slice saved by numpy is written in C order again.
    let sliced = read("sliced.npy").unwrap();
    assert_eq!(sliced.shape, vec![2, 3, 4, 9]);
    assert_eq!(sliced.data[36], a4[72]);

    for (name, expect) in [
        ("fortran.npy", "fortran_order True"),
        ("big.npy", "'>f4'"),
        ("int.npy", "'<i8'"),
        ("half.npy", "'<f2'"),
        ("object.npy", "'|O'"),
        ("structured.npy", "structured dtype"),
    ] {
        let e = read(name).unwrap_err().to_string();
        assert!(e.starts_with(&format!("{name}: ")) && e.contains(expect), "{name}: {e}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A reader that hands out at most `step` bytes per call, like a pipe.
struct Trickle<'a> {
    data: &'a [u8],
    step: usize,
}

impl Read for Trickle<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.step.min(buf.len()).min(self.data.len());
        buf[..n].copy_from_slice(&self.data[..n]);
        self.data = &self.data[n..];
        Ok(n)
    }
}

/// A reader that fails after some bytes.
struct Failing<'a> {
    data: &'a [u8],
}

impl Read for Failing<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        if self.data.is_empty() {
            return Err(std::io::Error::other("device on fire"));
        }
        let n = buf.len().min(self.data.len());
        buf[..n].copy_from_slice(&self.data[..n]);
        self.data = &self.data[n..];
        Ok(n)
    }
}

#[test]
fn reads_through_pipes_and_reports_io_errors() {
    let data = values(2 * 5 * 4 * 9);
    let bytes = npy::to_bytes(&[2, 5, 4, 9], &data).unwrap();
    for step in [1, 3, 7, 64, 4096] {
        let got = npy::read(&mut Trickle { data: &bytes, step }, "pipe").unwrap();
        assert_eq!(got.data, data, "step {step}");
    }
    // Writing to a pipe needs no seeking either: write into a Vec and compare.
    let mut out = Vec::new();
    npy::write_f32(&mut out, &[2, 5, 4, 9], &data).unwrap();
    assert_eq!(out, bytes);
    let e = npy::read(&mut Failing { data: &bytes[..100] }, "dev").unwrap_err();
    assert!(matches!(e, NpyError::Io { .. }) && e.to_string().contains("dev: device on fire"), "{e}");
}

/// xorshift64*, seeded: the mutation test is reproducible.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Header fragments worth splicing in: they reach the parser's less travelled paths.
const SPLICES: &[&[u8]] = &[
    b"(",
    b")",
    b",",
    b"'",
    b"\"",
    b"{",
    b"}",
    b"[",
    b"True",
    b"False",
    b"99999999999999999999999",
    b"18446744073709551615",
    b"4294967296",
    b"'<f8'",
    b"'>f4'",
    b"L",
    b"\\",
    b"\xff\xfe",
    b"\n",
    b"'shape': (1, 2), ",
    b"'descr': ",
];

#[test]
fn mutated_files_never_panic() {
    let mut bases: Vec<Vec<u8>> = Vec::new();
    for shape in shapes() {
        let n: usize = shape.iter().product();
        bases.push(npy::to_bytes(&shape, &values(n)).unwrap());
    }
    // A float64 and a version-2 file too.
    let dict = b"{'descr': '<f8', 'fortran_order': False, 'shape': (3, 2), }\n";
    let mut v2 = b"\x93NUMPY\x02\x00".to_vec();
    v2.extend_from_slice(&(dict.len() as u32).to_le_bytes());
    v2.extend_from_slice(dict);
    v2.extend((0..6).flat_map(|i| (i as f64 * 1.5).to_le_bytes()));
    assert_eq!(npy::from_bytes(&v2, "v2").unwrap().data, vec![0.0, 1.5, 3.0, 4.5, 6.0, 7.5]);
    bases.push(v2);

    let mut rng = Rng(0x5EED_1234_ABCD_0001);
    let (mut accepted, mut refused) = (0usize, 0usize);
    // MENAGERIE_NPY_MUTATIONS=N runs a longer campaign (e.g. in release mode).
    let rounds = std::env::var("MENAGERIE_NPY_MUTATIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(20_000usize);
    for _ in 0..rounds {
        let mut b = bases[rng.below(bases.len())].clone();
        for _ in 0..1 + rng.below(4) {
            // Mutations favour the header (the first ~128 bytes), where the parsing is.
            let hot = b.len().min(140);
            match rng.below(6) {
                0 if !b.is_empty() => {
                    let i = rng.below(hot);
                    b[i] ^= 1 << rng.below(8);
                }
                1 if !b.is_empty() => {
                    let i = rng.below(hot);
                    b[i] = rng.next() as u8;
                }
                2 => {
                    let at = rng.below(b.len() + 1);
                    b.truncate(at);
                }
                3 if !b.is_empty() => {
                    let i = rng.below(hot);
                    let n = 1 + rng.below(8);
                    b.drain(i..(i + n).min(b.len()));
                }
                4 => {
                    let i = rng.below(hot.min(b.len()) + 1);
                    let s = SPLICES[rng.below(SPLICES.len())];
                    b.splice(i..i, s.iter().copied());
                }
                _ => {
                    // Rewrite the header length field.
                    if b.len() >= 10 {
                        let v = (rng.next() as u16).to_le_bytes();
                        b[8] = v[0];
                        b[9] = v[1];
                    }
                }
            }
        }
        match npy::read(&mut Trickle { data: &b, step: 1 + rng.below(50) }, "m.npy") {
            Ok(a) => {
                assert_eq!(a.shape.iter().product::<usize>(), a.data.len());
                accepted += 1;
            }
            Err(e) => {
                let msg = e.to_string();
                assert!(msg.starts_with("m.npy: ") && !msg.contains('\n'), "{msg:?}");
                refused += 1;
            }
        }
    }
    eprintln!("mutations: {accepted} still valid, {refused} refused");
    assert!(refused > rounds / 2, "the mutations should mostly break files ({refused} of {rounds})");
}

#[test]
fn huge_claims_cost_only_what_the_input_holds() {
    // A header claiming ~2^62 bytes of data over a tiny input must fail fast, not allocate.
    let dict = "{'descr': '<f4', 'fortran_order': False, 'shape': (1073741824, 1073741824), }";
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    b.extend_from_slice(dict.as_bytes());
    b.extend_from_slice(&[0; 16]);
    let e = npy::from_bytes(&b, "huge.npy").unwrap_err().to_string();
    assert!(e.contains("needs 4611686018427387904 data bytes but the input has 16"), "{e}");
    let dict = "{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 4294967296), }";
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend_from_slice(&(dict.len() as u16).to_le_bytes());
    b.extend_from_slice(dict.as_bytes());
    let e = npy::from_bytes(&b, "huge.npy").unwrap_err().to_string();
    assert!(e.contains("too large"), "{e}");
}
