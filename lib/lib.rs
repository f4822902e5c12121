//! menagerie: animate any skeleton from the command line.
//!
//! The library behind the binaries in `bins/`: data types and utilities at the bottom (`bvh`,
//! `skeleton`, `motion`, `rng`, `linalg`), then documents and I/O (`document`, `io`), then
//! tools (`synth`, `cli`).

pub mod augment;
pub mod binding;
pub mod budget;
pub mod bvh;
pub mod cli;
pub mod diffusion;
pub mod dift;
pub mod document;
pub mod embed;
pub mod io;
pub mod linalg;
pub mod metrics;
pub mod motion;
pub mod nn;
pub mod render;
pub mod repr;
pub mod retarget;
pub mod rng;
pub mod sata;
pub mod segment;
pub mod skeleton;
pub mod synth;
