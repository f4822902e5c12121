//! A training run's progress as text: the status after a step (count, loss, speed, time left)
//! and a bar. `diffusion::trainer::train_loop` reports `Progress`; how it reads is fixed here,
//! beside it, so that every caller of the loop shows the same line.

use super::trainer::Progress;

/// Seconds as `1h02m`, `3m05s` or `42s`.
pub fn duration(seconds: f64) -> String {
    if !seconds.is_finite() {
        return "?".into();
    }
    let s = seconds.max(0.0).round() as u64;
    match s {
        0..=59 => format!("{s}s"),
        60..=3599 => format!("{}m{:02}s", s / 60, s % 60),
        _ => format!("{}h{:02}m", s / 3600, (s % 3600) / 60),
    }
}

/// `[######..............]` for `done` of `total`, `width` cells inside the brackets.
pub fn bar(done: u64, total: u64, width: usize) -> String {
    let filled = if total == 0 { width } else { ((done.min(total) as u128 * width as u128) / total as u128) as usize };
    format!("[{}{}]", "#".repeat(filled), ".".repeat(width - filled))
}

impl Progress {
    /// The last step of the run: the step count or the time budget reached.
    pub fn is_last(&self) -> bool {
        self.step == self.steps || self.budget_used.is_some_and(|u| u >= 1.0)
    }

    /// `step 5/10  loss 0.1234  2.00 steps/s  ETA 3s`; with a time budget and no step limit
    /// given (`steps_given` false) the count has no total and the time is what is left.
    pub fn status(&self, steps_given: bool) -> String {
        let (step, steps, loss, rate, eta) = (self.step, self.steps, self.loss, self.rate, duration(self.eta_seconds));
        let count = match (self.budget_used, steps_given) {
            (Some(_), false) => format!("step {step}"),
            _ => format!("step {step:>width$}/{steps}", width = steps.to_string().len()),
        };
        let left = match self.budget_used {
            Some(_) => format!("{eta} left"),
            None => format!("ETA {eta}"),
        };
        format!("{count}  loss {loss:.4}  {rate:.2} steps/s  {left}")
    }

    /// The bar, `width` cells: filled with the time budget when there is one, else with steps.
    pub fn bar(&self, width: usize) -> String {
        match self.budget_used {
            Some(u) => bar((u * 1000.0).round() as u64, 1000, width),
            None => bar(self.step, self.steps, width),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_and_bars() {
        assert_eq!(duration(42.4), "42s");
        assert_eq!(duration(185.0), "3m05s");
        assert_eq!(duration(3720.0), "1h02m");
        assert_eq!(duration(f64::NAN), "?");
        assert_eq!(bar(5, 10, 4), "[##..]");
        assert_eq!(bar(0, 0, 3), "[###]");
        let p = Progress { step: 5, steps: 10, loss: 0.5, rate: 2.0, eta_seconds: 3.0, budget_used: None };
        assert_eq!(p.status(true), "step  5/10  loss 0.5000  2.00 steps/s  ETA 3s");
        assert!(!p.is_last());
    }
}
