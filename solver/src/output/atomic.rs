//! Atomic file writes: the content goes to a temporary file beside the target, is flushed to
//! disk, and is then renamed over the target, so a reader never sees a half-written file and an
//! interrupted run leaves the old file (or none) behind. Every writer of the workspace goes
//! through here.

use std::io::Write;
use std::path::Path;

/// Write `bytes` to `path` atomically (temporary `NAME.EXT.tmp` beside it).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let tmp = path.with_extension(match path.extension() {
        Some(e) => format!("{}.tmp", e.to_string_lossy()),
        None => "tmp".into(),
    });
    write_atomic_with(path, &tmp, |tmp| {
        let mut f = std::fs::File::create(tmp).map_err(|e| e.to_string())?;
        f.write_all(bytes).map_err(|e| e.to_string())
    })
}

/// Write `path` atomically through `write`, which creates the temporary file `tmp` (beside
/// `path`, on the same file system) by whatever means the format needs. The temporary is flushed
/// to disk and renamed over `path`; on any error it is removed and the error names `path`.
pub fn write_atomic_with(
    path: &Path,
    tmp: &Path,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), String> {
    let res = write(tmp).and_then(|_| {
        let sync = std::fs::File::open(tmp).and_then(|f| f.sync_data());
        sync.and_then(|_| std::fs::rename(tmp, path))
            .map_err(|e| e.to_string())
    });
    res.map_err(|e| {
        let _ = std::fs::remove_file(tmp);
        format!("{}: cannot write: {e}", path.display())
    })
}
