//! The BVH reader and writer on every real corpus file: everything parses, joint counts match
//! the ROOT/JOINT entries, and the write-back round trip is exact.
use crate::common;

use menagerie::bvh;

#[test]
fn every_corpus_file_parses_and_round_trips() {
    let Some(data) = common::shared_data("every_corpus_file_parses_and_round_trips") else { return };
    for path in common::corpus_bvh_files(&data) {
        let text = std::fs::read(&path).unwrap();
        let name = path.display().to_string();
        let a = bvh::parse_bytes(&text, &name).unwrap_or_else(|e| panic!("{e}"));
        let entries = String::from_utf8_lossy(&text).lines().filter(|l| matches!(l.split_whitespace().next(), Some("ROOT") | Some("JOINT"))).count();
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

/// Motion -> Euler channels -> Motion keeps every world position: the decomposition used when
/// writing generated motion back to BVH is exact for every channel order in the corpus.
#[test]
fn motion_written_back_as_euler_channels_has_the_same_fk() {
    use menagerie::motion::Motion;
    use menagerie::skeleton::Skeleton;
    let Some(data) = common::shared_data("motion_written_back_as_euler_channels_has_the_same_fk") else { return };
    let mut worst = 0.0f64;
    for path in common::corpus_bvh_files(&data) {
        let name = path.display().to_string();
        let a = bvh::read_path(&path).unwrap();
        let skeleton = Skeleton::from_bvh(&a);
        let motion = Motion::from_bvh(&a, &skeleton);
        let written = bvh::write_string(&motion.to_bvh(&skeleton));
        let b = bvh::parse(&written, &name).unwrap();
        let again = Motion::from_bvh(&b, &Skeleton::from_bvh(&b));
        let (pa, pb) = (motion.forward_kinematics(&skeleton), again.forward_kinematics(&skeleton));
        let scale = skeleton.rest_extent().max(1e-9);
        for (x, y) in pa.positions.iter().zip(&pb.positions) {
            worst = worst.max(x.distance(*y) / scale);
        }
    }
    eprintln!("worst FK change after Euler write-back: {worst:.3e} of the skeleton extent");
    assert!(worst < 1e-9, "Euler write-back moved joints by {worst:.3e} of the extent");
}
