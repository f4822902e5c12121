//! menagerie: animate any skeleton from the command line.
//!
//! The library behind the binaries in `bins/`. Its modules stack in floors, each using only its
//! own floor and those below; docs/ARCHITECTURE.md describes them, the formats between the tools
//! and each tool's data flow, and docs/reference/ the facts taken from the reference code.
//!
//! Utilities:
//! * [`rng`]: the seeded generator, independent streams and normal values behind all randomness.
//! * [`linalg`]: dense symmetric linear algebra (eigenvalues, covariance, PSD square root) in f64.
//! * [`budget`]: the memory budget an allocation sized from input is checked against first.
//! * [`io`]: `-` as stdin/stdout, atomic all-or-nothing file output, NPY.
//!
//! Data types:
//! * [`bvh`]: our BVH reader and writer (f64 values, exact round trip, file:line errors).
//! * [`gltf`]: glTF 2.0 / GLB in (a skin and one animation) and out (skin, animation, stick mesh).
//! * [`skeleton`]: the joint tree, topology (relations, distances, chains), names, sides, feet.
//! * [`motion`]: per-frame local rotations and translations, Euler channels, forward kinematics.
//! * [`repr`]: feature tensors of a motion (AnyTop's 13 per joint, Motion2Motion's) and back.
//!
//! Skeleton descriptions and edits:
//! * [`document`]: the skeleton document (JSON) `skel-info` prints and the tools read.
//! * [`input`]: what tools are given, read: skeleton files, motion files, NPY features on a skeleton.
//! * [`encode`]: clips of one skeleton as one feature batch, with the rig, placements and statistics.
//! * [`embed`]: joint-name text embeddings, offline (a built-in MiniLM table).
//! * [`binding`]: bone bindings between two skeletons, from a file or automatic.
//! * [`ood`]: how far a skeleton lies from a model's training skeletons (the OOD warning).
//! * [`augment`]: skeletal augmentation (remove chains, subdivide bones), motion kept exact.
//!
//! Algorithms:
//! * [`nn`]: AnyTop's denoiser on candle (CPU).
//! * [`diffusion`]: noise schedule, samplers, training data and loop, checkpoints, editing.
//! * [`sata`]: the SATA topology-agnostic autoencoder (latents for any skeleton).
//! * [`dift`]: diffusion features, joint and frame correspondence.
//! * `patch` (crate-private): the patch machinery GenMM and Motion2Motion share (channels,
//!   pyramid lengths, patch nearest neighbours and blending).
//! * [`genmm`]: example-based generation from a few clips of a skeleton, no training (GenMM).
//! * [`retarget`]: Motion2Motion retargeting (patch nearest neighbours over a pyramid).
//! * [`metrics`]: the papers' metrics, movement and physics scores.
//! * [`edit`]: the everyday edits of a clip (`mo-edit`): time, axes, scale, mirror, root, rest
//!   pose, names, foot locking.
//! * [`segment`]: temporal segmentation of a motion into actions.
//! * [`render`]: contact sheets (PNG), GIF and an HTML viewer.
//! * [`synth`]: procedural creatures and gaits, the project's own example data.
//!
//! Tools:
//! * [`cli`]: what the binaries share: options, loading, output, one-line errors, exit codes.

pub mod augment;
pub mod binding;
pub mod budget;
pub mod bvh;
pub mod cli;
pub mod correspond;
pub mod diffusion;
pub mod dift;
pub mod document;
pub mod edit;
pub mod embed;
pub mod encode;
pub mod genmm;
pub mod gltf;
pub mod input;
pub mod io;
pub mod linalg;
pub mod metrics;
pub mod motion;
pub mod nn;
pub mod ood;
pub(crate) mod patch;
pub mod render;
pub mod repr;
pub mod retarget;
pub mod rng;
pub mod sata;
pub mod segment;
pub mod skeleton;
pub mod synth;
