//! The project's data a command reads, compiled into the binary (issue 27):
//! the budget profiles (`profiles/*.toml`), the measured accuracy tables
//! (`profiles/accuracy/`) and the planner's stored frames
//! (`profiles/frames/plan/`). A copied or installed binary runs anywhere;
//! a user's own profile is still given by path. tools/build.rs writes the
//! table; a test holds it to the folders.

include!(concat!(env!("OUT_DIR"), "/embedded.rs"));

/// The text of the embedded file at `path` (relative to the project:
/// `profiles/xbox360.toml`).
pub fn file(path: &str) -> Option<&'static str> {
    FILES
        .binary_search_by(|(p, _)| (*p).cmp(path))
        .ok()
        .map(|i| FILES[i].1)
}

/// The embedded files directly in folder `dir` whose names end with
/// `suffix`, sorted: (file name, text).
pub fn files_in(dir: &str, suffix: &str) -> Vec<(&'static str, &'static str)> {
    let prefix = format!("{}/", dir.trim_end_matches('/'));
    FILES
        .iter()
        .filter_map(|(p, text)| {
            let name = p.strip_prefix(prefix.as_str())?;
            (!name.contains('/') && name.ends_with(suffix)).then_some((name, *text))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    // The table is the folders' data files, every one, byte for byte: the
    // binary carries what the source tree holds.
    #[test]
    fn the_table_is_the_folders() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let mut on_disk = Vec::new();
        for dir in ["profiles", "profiles/accuracy", "profiles/frames/plan"] {
            for e in std::fs::read_dir(root.join(dir)).unwrap() {
                let p = e.unwrap().path();
                let ext = p.extension().and_then(|x| x.to_str());
                if p.is_file() && matches!(ext, Some("toml" | "json")) {
                    let rel = p.strip_prefix(root).unwrap().to_string_lossy().to_string();
                    on_disk.push((rel, std::fs::read_to_string(&p).unwrap()));
                }
            }
        }
        on_disk.sort();
        let embedded: Vec<(String, String)> = FILES
            .iter()
            .map(|(p, t)| (p.to_string(), t.to_string()))
            .collect();
        assert_eq!(embedded.len(), on_disk.len());
        assert!(
            embedded == on_disk,
            "the embedded data differ from the folders"
        );
        assert!(file("profiles/xbox360.toml").is_some());
        assert!(file("profiles/none.toml").is_none());
        let profiles = files_in("profiles", ".toml");
        assert!(profiles.iter().any(|(n, _)| *n == "xbox360.toml"));
        assert!(!profiles.iter().any(|(n, _)| n.contains('/')));
        let plan = files_in("profiles/frames/plan", ".json");
        assert!(
            plan.iter().any(|(n, _)| *n == "index.json"),
            "{}",
            plan.len()
        );
    }
}
