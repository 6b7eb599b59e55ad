//! `history.csv`: one row per history interval with time, step, energies, the energy error and
//! the reaction forces of the requested node sets. Rows are kept in memory and the file is
//! rewritten atomically at each flush, so it is never half-written.

use super::atomic::write_atomic;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// A history table being written.
pub struct History {
    path: PathBuf,
    columns: Vec<String>,
    body: String,
    rows: usize,
}

impl History {
    /// Start a table with these columns.
    pub fn new(path: &Path, columns: Vec<String>) -> History {
        History {
            path: path.to_path_buf(),
            columns,
            body: String::new(),
            rows: 0,
        }
    }
    /// Column names.
    pub fn columns(&self) -> &[String] {
        &self.columns
    }
    /// Append one row (must match the columns).
    pub fn push(&mut self, values: &[f64]) {
        debug_assert_eq!(values.len(), self.columns.len());
        for (i, v) in values.iter().enumerate() {
            if i > 0 {
                self.body.push(',');
            }
            let _ = write!(self.body, "{v:.9e}");
        }
        self.body.push('\n');
        self.rows += 1;
    }
    /// Rows written.
    pub fn rows(&self) -> usize {
        self.rows
    }
    /// Write the file atomically.
    pub fn flush(&self) -> Result<(), String> {
        let mut s = self.columns.join(",");
        s.push('\n');
        s.push_str(&self.body);
        write_atomic(&self.path, s.as_bytes())
    }
}

/// Read a history CSV back: (columns, rows).
pub fn read_history(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let s = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = s.lines();
    let cols: Vec<String> = lines
        .next()
        .ok_or("empty history")?
        .split(',')
        .map(|c| c.to_string())
        .collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|x| {
                    x.parse::<f64>()
                        .map_err(|e| format!("{}: {e}", path.display()))
                })
                .collect()
        })
        .collect::<Result<Vec<Vec<f64>>, String>>()?;
    Ok((cols, rows))
}

/// The value of column `name` in every row.
pub fn column(cols: &[String], rows: &[Vec<f64>], name: &str) -> Option<Vec<f64>> {
    let i = cols.iter().position(|c| c == name)?;
    Some(rows.iter().map(|r| r[i]).collect())
}
