//! A retargeted sample's report as lines of text, for `mo-retarget --report`.
//!
//! The report is what a user reads to judge a transfer (how much the source constrained, how
//! well patches matched at each level); written here, beside the numbers it describes, so that
//! any caller prints the same thing.

use super::Report;

impl Report {
    /// Lines about this sample (made with `seed`): its size and timing, one line per pyramid
    /// level with the match cost of each step, and its notes. Lines after the first are
    /// indented by two spaces.
    pub fn describe(&self, index: usize, seed: u64) -> Vec<String> {
        let mut lines = vec![format!(
            "sample {index} (seed {seed}): {} frames ({} constrained by the source), patch {}, {} of {} channels bound, synthesis {:.1} ms",
            self.frames,
            self.known_frames,
            self.patch,
            self.bound_channels,
            self.channels,
            self.timings.synthesis.as_secs_f64() * 1e3
        )];
        for (l, level) in self.levels.iter().enumerate() {
            let costs: Vec<String> = level.step_costs.iter().map(|c| format!("{c:.4}")).collect();
            lines.push(format!(
                "  level {l}: {} frames, {} example patches, {} steps, match cost per step [{}]",
                level.frames,
                level.example_patches,
                level.steps,
                costs.join(", ")
            ));
        }
        lines.extend(self.notes.iter().map(|note| format!("  note: {note}")));
        lines
    }
}
