//! `palpa material FILE.toml [--out FILE.csv]`: the material-point driver. One law through a
//! prescribed homogeneous path (see `material::driver` for the file format and the columns).

use solver::output::atomic::write_atomic;
use std::path::Path;

/// Run a driver file; print the CSV to stdout, or write it atomically to `out`.
pub fn material(file: &Path, out: Option<&Path>) -> Result<(), String> {
    // `run_driver_file` names the file in every error (read, TOML line and key, law checks).
    let csv = ::material::driver::run_driver_file(file)?;
    match out {
        None => {
            use std::io::Write;
            let mut so = std::io::stdout().lock();
            // A closed pipe (`palpa material f.toml | head`) is not an error worth a message.
            match so.write_all(csv.as_bytes()).and_then(|_| so.flush()) {
                Ok(()) => Ok(()),
                Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
                Err(e) => Err(format!("cannot write to stdout: {e}")),
            }
        }
        Some(path) => {
            if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
                std::fs::create_dir_all(dir)
                    .map_err(|e| format!("{}: cannot create directory: {e}", dir.display()))?;
            }
            write_atomic(path, csv.as_bytes())?;
            let rows = csv.lines().count().saturating_sub(1);
            let cols = csv
                .lines()
                .next()
                .map(|h| h.split(',').count())
                .unwrap_or(0);
            eprintln!(
                "{}: wrote {} rows x {} columns to {}",
                file.display(),
                rows,
                cols,
                path.display()
            );
            Ok(())
        }
    }
}
