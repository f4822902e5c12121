//! Patch-based motion synthesis: the machinery that GenMM (`genmm`, example-based generation)
//! and Motion2Motion (`retarget`, transfer) share, so neither has its own copy.
//!
//! Both methods work on per-frame channel vectors (`channels`: local 6D rotations of every
//! joint plus the root's dx, y, dz), over a pyramid of lengths in time (`pyramid`), and refine
//! a synthesis by replacing each of its patches (a few consecutive frames) by the nearest patch
//! of the example clips and averaging the overlapping choices (`nn`, a nearest-neighbour
//! search, not a neural network). What differs is what steers the synthesis: a source motion's
//! bound channels for Motion2Motion, nothing but a random start (and optionally kept parts of a
//! reference clip) for GenMM.

pub(crate) mod channels;
pub(crate) mod nn;
pub(crate) mod pyramid;
