//! How often each one-time check of a command ran (issue 27: every check is
//! made once, before any device opens, and nothing below checks again).
//! Each check notes itself here; `DERMIS_CHECK_COUNTS=1 dermis ...` prints
//! the counts to standard error when the command ends, which is how the
//! tests hold a command to one settings check, one group resolution, one
//! frame-count check and one preparation of its outputs (tests/suite/cli.rs).

use std::collections::BTreeMap;
use std::sync::Mutex;

static COUNTS: Mutex<BTreeMap<&'static str, u32>> = Mutex::new(BTreeMap::new());

/// Notes that `check` ran once more.
pub fn ran(check: &'static str) {
    // A poisoned lock only means a panic elsewhere: the counts stay usable.
    let mut c = COUNTS.lock().unwrap_or_else(|e| e.into_inner());
    *c.entry(check).or_default() += 1;
}

/// Every check that ran, with its count.
pub fn counts() -> BTreeMap<&'static str, u32> {
    COUNTS.lock().unwrap_or_else(|e| e.into_inner()).clone()
}

/// The counts as one line: `checks: groups=1 settings=1 ...`.
pub fn line() -> String {
    let parts: Vec<String> = counts()
        .iter()
        .map(|(k, v)| format!("{}={v}", k.replace(' ', "-")))
        .collect();
    format!("checks: {}", parts.join(" "))
}

#[cfg(test)]
mod tests {
    #[test]
    fn counts_add_up_by_name() {
        super::ran("a test check");
        super::ran("a test check");
        assert_eq!(super::counts()["a test check"], 2);
        assert!(
            super::line().contains("a-test-check=2"),
            "{}",
            super::line()
        );
    }
}
