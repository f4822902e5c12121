//! Fuzz the glTF reader (see `lib/gltf/mod.rs`): the `gltf` crate parses and validates, and
//! what it leaves to us (buffer lengths, accessor types and counts, node cycles, key times,
//! finite numbers) is checked before we index with it.
//!
//! For any bytes: reading must not panic, hang or allocate wildly. When the bytes read, the GLB
//! we write of the result must read back with the same joints and frames.
#![no_main]

use libfuzzer_sys::fuzz_target;
use menagerie::gltf::{read, write_glb, ReadOptions};

fuzz_target!(|data: &[u8]| {
    let options = ReadOptions { max_frames: 10_000, ..ReadOptions::default() };
    let Ok((skeleton, motion)) = read(data, "fuzz.glb", None, &options) else { return };
    let written = write_glb(&skeleton, &motion, "written.glb").expect("writing what was read");
    let (s2, m2) = read(&written, "written.glb", None, &options).unwrap_or_else(|e| panic!("our GLB does not read back: {e}"));
    assert_eq!(s2.joints.len(), skeleton.joints.len());
    assert_eq!(m2.frames, motion.frames);
});
