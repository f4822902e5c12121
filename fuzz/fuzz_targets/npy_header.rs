//! Fuzz the NPY reader (`io::npy::from_bytes`): magic, version, header dictionary, shape, data.
//!
//! For any bytes: reading must not panic, hang or allocate wildly (the data length is checked
//! against the shape before anything is allocated for it). An accepted array holds exactly the
//! values its shape says, and writing it back reads back equal.
#![no_main]

use libfuzzer_sys::fuzz_target;
use menagerie::io::npy;

fuzz_target!(|data: &[u8]| {
    let Ok(array) = npy::from_bytes(data, "fuzz") else { return };
    let count: usize = array.shape.iter().product();
    assert_eq!(count, array.data.len(), "shape {:?}", array.shape);
    let written = npy::to_bytes(&array.shape, &array.data).expect("an accepted array writes");
    let back = npy::from_bytes(&written, "written").expect("a written array reads back");
    assert_eq!(back.shape, array.shape);
    assert!(back.data.iter().zip(&array.data).all(|(a, b)| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())));
});
