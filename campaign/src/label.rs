//! Labels of locations and runs: each names a directory under `runs/`.

/// A location label names a directory: letters, digits, `-`, `_`, `.`, not starting with `.`.
pub fn check_label(l: &str) -> Result<(), String> {
    if l.is_empty()
        || !l
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.'))
        || l.starts_with('.')
    {
        return Err(format!(
            "location label `{l}`: use letters, digits, `-`, `_` and `.` (it names a directory)"
        ));
    }
    Ok(())
}
