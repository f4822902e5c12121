//! Settings of a retarget run, with the paper's defaults (Motion2Motion §4.1, table 5) and the
//! reference code's pyramid and noise values (docs/reference/motion2motion.md §3.3).

use super::RetargetError;

/// How the source rotation of a bound joint becomes the target joint's local rotation.
///
/// The default stays the reference's `Local`: measured with `mo-metrics transfer` on
/// Flamingo <-> Monkey (reference and auto bindings) and three synthetic pairs
/// (docs/retarget-results.md), `Aligned` is within 0.002 (frequency alignment) / 0.01 (contacts) of `Local` (the bound
/// channels end up blended example data, so the conversion barely shows) and `World` wins one
/// pair (spider -> crab, frequency alignment 0.83 vs 0.05) but loses clearly on three
/// (Flamingo -> Monkey auto 0.79 vs 0.93, Monkey -> Flamingo 0.89 vs 0.92, quadruped -> dragon
/// 0.90 vs 0.93): no variant is better by the numbers across pairs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum BoundRotation {
    /// The source's local rotation, copied as is (the reference's behaviour).
    #[default]
    Local,
    /// The source's local rotation expressed about the target bone: conjugated by the rest
    /// rotation that turns the target bone direction onto the source's, so a bone that points
    /// down the -y axis on one skeleton and along +z on the other still swings the same way.
    Aligned,
    /// The target joint gets the source joint's orientation relative to the root (world
    /// rotation with the root's removed), whatever its parents do.
    World,
}

/// Where the target root's trajectory (horizontal velocity and height) comes from.
///
/// The default stays `Examples`: `Source` changed frequency alignment by -0.026..+0.010 and
/// contact consistency by -0.006..+0.008 on the same pairs (mostly down): no gain; it is
/// for sources that travel while the examples walk in place.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum RootMotion {
    /// Synthesised from the examples like any unbound channel (the reference's behaviour).
    #[default]
    Examples,
    /// The source's root trajectory scaled by the ratio of the skeletons' hip heights; the root
    /// position channels are then bound channels.
    Source,
}

/// The per-frame features patches are matched on (paper table 4). Blending always carries the
/// rotation features too, which is what the output is decoded from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum Repr {
    /// Local 6D rotations of every joint plus the root's dx, y, dz (the paper's default).
    #[default]
    Rotation,
    /// World joint velocities (per frame) plus the root's dx, y, dz.
    Velocity,
    /// Joint positions relative to the root (translation only) plus the root's dx, y, dz.
    Position,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    /// Patch length in frames (paper: 11). Shrunk to the longest example / the output when
    /// those are shorter; the report says so.
    pub patch: usize,
    /// Weight of the bound channels in the match distance (paper: 0.85); unbound channels get
    /// 1 - alpha. Like the reference, the weight multiplies the values, so distances weigh
    /// alpha².
    pub alpha: f32,
    /// Matching-and-blending iterations per pyramid level (paper's L: 3).
    pub steps: usize,
    /// Length ratio between consecutive pyramid levels (reference: 0.75).
    pub pyramid: f64,
    /// The coarsest level holds about `coarse_patches * patch` example frames (reference: 5).
    pub coarse_patches: f64,
    /// Completeness normalisation of GenMM (reference: 0.01): each example patch's distances are
    /// divided by this plus its distance to its closest query patch, so unused example patches
    /// are preferred. `None` turns it off (plain nearest neighbours).
    pub completeness: Option<f32>,
    /// Overwrite the bound channels with the source's after synthesis (paper table 6, "directly
    /// copy"; the reference's `retargeting_copy`).
    pub copy_bound: bool,
    pub bound_rotation: BoundRotation,
    pub root_motion: RootMotion,
    pub repr: Repr,
    /// Output length in frames; `None` = the source's length. Frames past the end of the
    /// source are synthesised from the examples (the source constrains nothing there).
    pub frames: Option<usize>,
    /// Key-frame mode: the source is known only at these frames; the others are synthesised.
    pub key_frames: Option<Vec<usize>>,
    /// Diversity: the first match of every pyramid level takes, for each query patch, one of
    /// its `sample_choices` nearest example patches, drawn from the seed; the level's other
    /// steps take the nearest. 1 = always the nearest, the reference's behaviour. The
    /// reference relies on its initial noise for diversity, but the bound channels (weight
    /// alpha² against (1 - alpha)² for the noisy ones) decide every match: on the
    /// Flamingo -> Monkey demo its seeds 0-4 give identical motions. Measured there
    /// (docs/retarget-results.md): 3 choices give 17x the diversity of 1 with the same
    /// frequency alignment, contact consistency and jitter; drawing at every step instead
    /// doubles the jitter, drawing only at the coarsest level washes out.
    pub sample_choices: usize,
    /// Standard deviation of the initial noise; like the reference, noise is wrapped into
    /// (-1, 1) by `fmod`, so the default 10 gives nearly uniform noise.
    pub noise_sigma: f64,
    pub seed: u64,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings {
            patch: 11,
            alpha: 0.85,
            steps: 3,
            pyramid: 0.75,
            coarse_patches: 5.0,
            completeness: Some(0.01),
            copy_bound: false,
            bound_rotation: BoundRotation::Local,
            root_motion: RootMotion::Examples,
            repr: Repr::Rotation,
            frames: None,
            key_frames: None,
            sample_choices: 3,
            noise_sigma: 10.0,
            seed: 0,
        }
    }
}

impl Settings {
    pub(crate) fn validate(&self) -> Result<(), RetargetError> {
        let bad = |what: &str, value: String, expected: &str| Err(RetargetError::Setting { what: what.to_string(), value, expected: expected.to_string() });
        if self.patch == 0 {
            return bad("patch", "0".into(), "at least 1 frame");
        }
        if self.sample_choices == 0 {
            return bad("sample_choices", "0".into(), "at least 1 candidate patch (1 = always the nearest)");
        }
        if self.steps == 0 {
            return bad("steps", "0".into(), "at least 1 matching step per level");
        }
        if !(0.0..=1.0).contains(&self.alpha) {
            return bad("alpha", self.alpha.to_string(), "a weight in [0, 1]");
        }
        if !(self.pyramid > 0.0 && self.pyramid < 1.0) {
            return bad("pyramid", self.pyramid.to_string(), "a ratio in (0, 1)");
        }
        if !(self.coarse_patches.is_finite() && self.coarse_patches > 0.0) {
            return bad("coarse_patches", self.coarse_patches.to_string(), "a positive number");
        }
        if let Some(c) = self.completeness {
            if !(c.is_finite() && c > 0.0) {
                return bad("completeness", c.to_string(), "a positive number");
            }
        }
        if !(self.noise_sigma.is_finite() && (0.0..=1e6).contains(&self.noise_sigma)) {
            return bad("noise_sigma", self.noise_sigma.to_string(), "a number in [0, 1e6]");
        }
        if self.frames == Some(0) {
            return Err(RetargetError::ZeroFrames { what: "the requested output".into() });
        }
        if let Some(k) = &self.key_frames {
            if k.is_empty() {
                return bad("key_frames", "[]".into(), "at least one key frame");
            }
        }
        Ok(())
    }
}
