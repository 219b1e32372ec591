//! The set-up test hook: every Vulkan object (or group made in one call)
//! created after the device opens is one creation step; steps are counted,
//! and a test can make the n-th from now fail as a driver's out-of-memory
//! would, to drive every error path of set-up (tests/teardown.rs).
//! `Context` holds one and forwards to it.

use std::sync::atomic::{AtomicUsize, Ordering};

use super::error::{Error, VkResult};

/// The creation counter and the pending failure.
pub struct Faults {
    /// Creations left before one is made to fail; `usize::MAX` when off.
    fail_countdown: AtomicUsize,
    /// Creation steps so far.
    creations: AtomicUsize,
}

impl Default for Faults {
    fn default() -> Self {
        Faults {
            fail_countdown: AtomicUsize::new(usize::MAX),
            creations: AtomicUsize::new(0),
        }
    }
}

impl Faults {
    /// The creation `n` steps from now (0: the next) fails; `None` turns it off.
    pub fn fail_after(&self, n: Option<usize>) {
        self.fail_countdown
            .store(n.unwrap_or(usize::MAX), Ordering::SeqCst);
    }

    /// Creation steps made so far.
    pub fn creations(&self) -> usize {
        self.creations.load(Ordering::SeqCst)
    }

    /// One creation step, of `what`: counted, and failed when the hook says
    /// so (once: the hook turns off after it fires).
    pub fn step(&self, what: &str) -> VkResult<()> {
        self.creations.fetch_add(1, Ordering::SeqCst);
        let left = self.fail_countdown.load(Ordering::SeqCst);
        if left == usize::MAX {
            return Ok(());
        }
        if left == 0 {
            self.fail_countdown.store(usize::MAX, Ordering::SeqCst);
            return Err(Error::Injected(what.to_string()));
        }
        self.fail_countdown.store(left - 1, Ordering::SeqCst);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_nth_step_fails_once_and_every_step_counts() {
        let f = Faults::default();
        assert!(f.step("a").is_ok());
        f.fail_after(Some(2));
        assert!(f.step("b").is_ok() && f.step("c").is_ok());
        match f.step("d") {
            Err(Error::Injected(what)) => assert_eq!(what, "d"),
            other => panic!("{other:?}"),
        }
        assert!(f.step("e").is_ok(), "the hook fires once");
        f.fail_after(Some(0));
        f.fail_after(None);
        assert!(f.step("f").is_ok());
        assert_eq!(f.creations(), 6);
    }
}
