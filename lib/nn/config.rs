//! The denoiser's hyper-parameters, with the paper's values and two smaller CPU presets.
//! Checkpoints carry this struct as JSON, so every field has a plain serde form.

use super::NnError;
use serde::{Deserialize, Serialize};

/// Number of relation types in R (self, parent, child, sibling, none, end effector;
/// docs/reference/anytop.md §2.4).
pub const RELATION_TYPES: usize = 6;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DenoiserConfig {
    /// Latent width of every token (the paper's F).
    pub width: usize,
    /// Number of skeletal-temporal layers.
    pub layers: usize,
    /// Attention heads (skeletal and temporal); `width` must be a multiple.
    pub heads: usize,
    /// Hidden width of the feed-forward block.
    pub ff: usize,
    /// Temporal attention window W: token i sees tokens k with |i-k| <= W/2, plus the rest-pose token.
    pub window: usize,
    /// Distances in D are capped at `dmax`; the distance tables have `dmax + 1` rows.
    pub dmax: usize,
    /// Size of the joint-name embeddings given in `Batch::names` (384 for all-MiniLM-L6-v2).
    pub name_dim: usize,
    /// Features per joint and frame (13 for the AnyTop representation).
    pub feature_dims: usize,
    /// Dropout probability. Only 0 is supported: the reference trains with 0.1, but dropout
    /// needs a seeded RNG threaded through training to stay reproducible, and at 0 the same
    /// forward serves training, sampling and DIFT features. `validate` rejects other values.
    pub dropout: f32,
    /// Layer-norm epsilon (PyTorch's 1e-5 in the reference).
    pub ln_eps: f64,
}

/// The model sizes the trainers offer (`mo-train --preset`), for the denoiser and SATA alike.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preset {
    Tiny,
    Compact,
    Small,
    Paper,
}

impl DenoiserConfig {
    /// The denoiser of a preset size.
    pub fn preset(preset: Preset) -> DenoiserConfig {
        match preset {
            Preset::Tiny => DenoiserConfig::tiny(),
            Preset::Compact => DenoiserConfig::compact(),
            Preset::Small => DenoiserConfig::small(),
            Preset::Paper => DenoiserConfig::paper(),
        }
    }

    /// The reference model (docs/reference/anytop.md §2.1): width 128, 4 layers, 4 heads, ff 1024,
    /// W 31, d_max 5; names are 384-d MiniLM embeddings instead of 768-d T5.
    pub fn paper() -> DenoiserConfig {
        DenoiserConfig { width: 128, layers: 4, heads: 4, ff: 1024, window: 31, dmax: 5, name_dim: 384, feature_dims: 13, dropout: 0.0, ln_eps: 1e-5 }
    }

    /// Half the width, a quarter of the feed-forward: about 8x fewer FLOPs per token than `paper`.
    pub fn small() -> DenoiserConfig {
        DenoiserConfig { width: 64, layers: 4, heads: 4, ff: 256, ..DenoiserConfig::paper() }
    }

    /// Twice tiny's width, two layers: a step costs about 2.4 times tiny's on one thread, and
    /// on the 71-skeleton zoo it reached tiny's loss in under half the steps (its 5,540 steps
    /// moved the zoo skeletons as much as tiny's 113,417; models/zoo-compact/MODEL_CARD.md).
    pub fn compact() -> DenoiserConfig {
        DenoiserConfig { width: 64, layers: 2, heads: 4, ff: 128, ..DenoiserConfig::paper() }
    }

    /// For tests and quick overfit checks: trains hundreds of steps in minutes on 2 cores.
    pub fn tiny() -> DenoiserConfig {
        DenoiserConfig { width: 32, layers: 2, heads: 2, ff: 64, ..DenoiserConfig::paper() }
    }

    pub fn head_dim(&self) -> usize {
        self.width / self.heads.max(1)
    }

    pub fn validate(&self) -> Result<(), NnError> {
        let bad = |field: &'static str, problem: String| Err(NnError::Config { field, problem });
        if self.width == 0 || self.layers == 0 || self.ff == 0 || self.feature_dims == 0 || self.name_dim == 0 {
            return bad("width/layers/ff/feature_dims/name_dim", format!("all must be > 0, got {self:?}"));
        }
        if self.heads == 0 || !self.width.is_multiple_of(self.heads) {
            return bad("heads", format!("must divide width {}, got {}", self.width, self.heads));
        }
        if self.width < 2 {
            return bad("width", format!("the sinusoidal embeddings need width >= 2, got {}", self.width));
        }
        if self.window == 0 {
            return bad("window", "must be >= 1".to_string());
        }
        if self.dropout != 0.0 {
            return bad("dropout", format!("only 0 is supported (see the field's documentation), got {}", self.dropout));
        }
        if !(self.ln_eps > 0.0 && self.ln_eps.is_finite()) {
            return bad("ln_eps", format!("must be positive and finite, got {}", self.ln_eps));
        }
        Ok(())
    }

    /// Number of scalar parameters the denoiser creates for this config (matches the VarMap).
    pub fn parameter_count(&self) -> usize {
        let (d, f, n) = (self.width, self.feature_dims, self.name_dim);
        let linear = |i: usize, o: usize| i * o + o;
        let input = 4 * linear(f, d) + linear(n, d);
        let topology = 2 * (self.dmax + 1) * d + 2 * RELATION_TYPES * d;
        let attention = 4 * linear(d, d);
        let layer = 2 * attention + linear(d, self.ff) + linear(self.ff, d) + 3 * 2 * d + linear(d, d);
        let output = 2 * linear(d, f);
        input + topology + self.layers * layer + output
    }
}

impl Default for DenoiserConfig {
    fn default() -> DenoiserConfig {
        DenoiserConfig::paper()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_validate_and_round_trip_through_json() {
        for cfg in [DenoiserConfig::paper(), DenoiserConfig::small(), DenoiserConfig::tiny()] {
            cfg.validate().unwrap();
            let json = serde_json::to_string(&cfg).unwrap();
            let back: DenoiserConfig = serde_json::from_str(&json).unwrap();
            assert_eq!(back, cfg);
        }
    }

    #[test]
    fn bad_configs_are_rejected() {
        let mut c = DenoiserConfig::tiny();
        c.heads = 3;
        assert!(matches!(c.validate(), Err(NnError::Config { field: "heads", .. })));
        let mut c = DenoiserConfig::tiny();
        c.dropout = 0.1;
        assert!(matches!(c.validate(), Err(NnError::Config { field: "dropout", .. })));
    }

    #[test]
    fn paper_parameter_count_matches_the_reference_minus_unused_modules() {
        // docs/reference/anytop.md §2.7: 1,762,714 effectively used parameters with 768-d T5 names;
        // our names are 384-d, which removes 384 * 128 weights from the name projection.
        assert_eq!(DenoiserConfig::paper().parameter_count(), 1_762_714 - 384 * 128);
    }
}
