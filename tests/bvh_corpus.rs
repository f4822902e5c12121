//! The BVH reader and writer on every real corpus file: everything parses, joint counts match
//! the ROOT/JOINT entries, and the write-back round trip is exact.
mod common;

use menagerie::bvh;

#[test]
fn every_corpus_file_parses_and_round_trips() {
    let Some(data) = common::shared_data("every_corpus_file_parses_and_round_trips") else { return };
    for path in common::corpus_bvh_files(&data) {
        let text = std::fs::read(&path).unwrap();
        let name = path.display().to_string();
        let a = bvh::parse_bytes(&text, &name).unwrap_or_else(|e| panic!("{e}"));
        let entries = String::from_utf8_lossy(&text)
            .lines()
            .filter(|l| matches!(l.split_whitespace().next(), Some("ROOT") | Some("JOINT")))
            .count();
        assert_eq!(a.joints.len(), entries, "{name}: joint count");
        assert_eq!(a.values.len(), a.frames * a.channel_count(), "{name}");
        assert!(a.frames >= 1, "{name}");
        // read -> write -> read reproduces every value (exactly, which is stronger than 1e-6).
        let w1 = bvh::write_string(&a);
        let b = bvh::parse(&w1, &name).unwrap_or_else(|e| panic!("re-reading written {name}: {e}"));
        assert_eq!(a, b, "{name}: read -> write -> read changed the data");
        // write -> read -> write is byte-identical.
        let w2 = bvh::write_string(&b);
        assert!(w1 == w2, "{name}: write -> read -> write is not byte-identical");
    }
}
