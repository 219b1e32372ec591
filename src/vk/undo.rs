//! Undoing what is made before a `Context` exists (the instance, the messenger,
//! the device): a closure run on drop unless disarmed. Apart from `guard.rs`,
//! which needs a `Context` to destroy through.

/// Runs `undo` on drop unless [`Undo::disarm`]ed: for what is made before a
/// `Context` exists to destroy through (the instance, the device).
pub struct Undo<F: FnOnce()>(Option<F>);

impl<F: FnOnce()> Undo<F> {
    pub fn new(undo: F) -> Self {
        Undo(Some(undo))
    }

    /// Set-up went through: the owner frees the object from now on.
    pub fn disarm(mut self) {
        self.0 = None;
    }
}

impl<F: FnOnce()> Drop for Undo<F> {
    fn drop(&mut self) {
        if let Some(f) = self.0.take() {
            f();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn undo_runs_unless_disarmed() {
        let ran = std::cell::Cell::new(0);
        drop(Undo::new(|| ran.set(ran.get() + 1)));
        assert_eq!(ran.get(), 1);
        Undo::new(|| ran.set(ran.get() + 1)).disarm();
        assert_eq!(ran.get(), 1);
        let early = || -> Result<(), ()> {
            let _u = Undo::new(|| ran.set(ran.get() + 10));
            Err(())?;
            Ok(())
        };
        assert!(early().is_err());
        assert_eq!(ran.get(), 11);
    }
}
