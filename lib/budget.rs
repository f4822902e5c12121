//! One memory budget for allocations sized from input.
//!
//! A number in a file or on the command line (a frame time of 1e-6 s, a frame count, a joint
//! count) can ask for more memory than any machine has; Rust then aborts, which is neither an
//! error message nor exit code 2. Code about to make such an allocation asks `check` first.

/// Bytes one allocation sized from input may take: far above any real clip or batch, well below
/// the memory of the machines this runs on.
pub const MAX_BYTES: u128 = 4 << 30;

#[derive(Debug, thiserror::Error)]
#[error("{what} would need {} MiB ({count} x {each} bytes), more than the {} MiB budget", need / (1 << 20), MAX_BYTES / (1 << 20))]
pub struct BudgetError {
    pub what: String,
    pub count: u128,
    pub each: u128,
    pub need: u128,
}

/// `count` items of `each` bytes for `what` (said in the error), within `MAX_BYTES`.
pub fn check(what: &str, count: u128, each: usize) -> Result<(), BudgetError> {
    let need = count.saturating_mul(each as u128);
    if need > MAX_BYTES {
        return Err(BudgetError { what: what.to_string(), count, each: each as u128, need });
    }
    Ok(())
}

/// Frames x joints of a motion (a rotation and a translation per joint and frame).
pub fn check_motion(what: &str, frames: usize, joints: usize) -> Result<(), BudgetError> {
    check(what, frames as u128 * joints as u128, std::mem::size_of::<glam::DQuat>() + std::mem::size_of::<glam::DVec3>())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn budget() {
        assert!(check_motion("a clip", 10_000, 100).is_ok());
        let e = check_motion("a clip", 1_000_000_000, 1_000).unwrap_err();
        assert!(e.to_string().starts_with("a clip would need"), "{e}");
        assert!(check("x", u128::MAX, 8).is_err());
    }
}
