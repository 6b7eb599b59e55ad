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

/// Read a history CSV back: (columns, rows). Every row must have exactly as many values as the
/// header has columns (a file cut mid-row is an error naming the file and the line, not a panic
/// later on when a column is looked up).
pub fn read_history(path: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>), String> {
    let s = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut lines = s.lines();
    let cols: Vec<String> = lines
        .next()
        .ok_or_else(|| format!("{}: empty history (no header line)", path.display()))?
        .split(',')
        .map(|c| c.to_string())
        .collect();
    let mut rows = Vec::new();
    for (k, l) in lines.enumerate() {
        let line = k + 2;
        let row = l
            .split(',')
            .map(|x| {
                x.parse::<f64>().map_err(|e| {
                    format!(
                        "{} line {line}: value `{x}` is not a number: {e}",
                        path.display()
                    )
                })
            })
            .collect::<Result<Vec<f64>, String>>()?;
        if row.len() != cols.len() {
            return Err(format!(
                "{} line {line}: {} values where the header has {} columns (file cut or damaged)",
                path.display(),
                row.len(),
                cols.len()
            ));
        }
        rows.push(row);
    }
    Ok((cols, rows))
}

/// The value of column `name` in every row.
pub fn column(cols: &[String], rows: &[Vec<f64>], name: &str) -> Option<Vec<f64>> {
    let i = cols.iter().position(|c| c == name)?;
    Some(rows.iter().map(|r| r[i]).collect())
}
