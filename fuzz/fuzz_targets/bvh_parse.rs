//! Fuzz the BVH reader and the writer's round-trip promises (see `lib/bvh/mod.rs`).
//!
//! For any bytes: parsing must not panic, hang or allocate wildly. When the bytes parse, the
//! written text must parse back to an equal `Bvh` (read -> write -> read is exact) and writing
//! that again must give the same bytes (write -> read -> write is byte-identical).
#![no_main]

use libfuzzer_sys::fuzz_target;
use menagerie::bvh;

fuzz_target!(|data: &[u8]| {
    let Ok(first) = bvh::parse_bytes(data, "fuzz") else { return };
    let w1 = bvh::write_string(&first);
    let second = match bvh::parse(&w1, "written") {
        Ok(b) => b,
        Err(e) => panic!("written text does not parse back: {e}\n--- written ---\n{w1}"),
    };
    assert_eq!(first, second, "read -> write -> read changed the data\n--- written ---\n{w1}");
    let w2 = bvh::write_string(&second);
    assert!(w1 == w2, "write -> read -> write is not byte-identical\n--- first ---\n{w1}\n--- second ---\n{w2}");
});
