//! Fuzz the skeleton-document reader (`SkeletonDocument::from_json`).
//!
//! For any text: reading must not panic, hang or allocate wildly. A document it accepts must
//! give its skeleton (the checks `from_json` makes are the ones every tool relies on), and
//! writing it and reading it back must be accepted again.
#![no_main]

use libfuzzer_sys::fuzz_target;
use menagerie::document::SkeletonDocument;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let Ok(doc) = SkeletonDocument::from_json(text) else { return };
    let skeleton = doc.skeleton().expect("an accepted document gives its skeleton");
    assert_eq!(skeleton.len(), doc.joint_count);
    let written = serde_json::to_string(&doc).expect("an accepted document serialises");
    if let Err(e) = SkeletonDocument::from_json(&written) {
        panic!("a written document does not read back: {e}\n{written}");
    }
});
