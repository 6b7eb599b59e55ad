//! JSON files of a campaign directory, read with the file named in every error and written
//! atomically.

use serde_json::Value;
use solver::output::atomic::write_atomic;
use std::path::Path;

/// Read a JSON file; an error names it.
pub fn read_json(path: &Path) -> Result<Value, String> {
    let s = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    serde_json::from_str(&s).map_err(|e| format!("{}: {e}", path.display()))
}

/// Write `v` as pretty JSON, atomically.
pub fn write_json(path: &Path, v: &Value) -> Result<(), String> {
    let s = serde_json::to_string_pretty(v).map_err(|e| e.to_string())?;
    write_atomic(path, s.as_bytes())
}
