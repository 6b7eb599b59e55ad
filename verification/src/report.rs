//! Rows, the printed table and the Markdown report.

use crate::CaseOutput;
use std::fmt::Write as _;

/// Outcome of one row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Within tolerance.
    Pass,
    /// Outside tolerance, or the case could not run.
    Fail,
    /// Reported for information; no tolerance stated.
    Info,
    /// The run stopped with an error that names the element and the time (hard cases).
    NamedStop,
    /// The feature the case needs does not exist yet.
    NotYet,
}

impl Status {
    /// Label in the table.
    pub fn label(&self) -> &'static str {
        match self {
            Status::Pass => "pass",
            Status::Fail => "FAIL",
            Status::Info => "info",
            Status::NamedStop => "pass (named stop)",
            Status::NotYet => "not yet",
        }
    }
}

/// One line of the verification table.
#[derive(Clone, Debug)]
pub struct Row {
    /// Case name.
    pub case: String,
    /// Quantity compared (with its unit, and how the error is measured).
    pub quantity: String,
    /// Where the reference value comes from.
    pub source: String,
    /// Reference value (NaN when there is none).
    pub reference: f64,
    /// palpa's value (NaN when the case did not produce one).
    pub value: f64,
    /// Error (relative unless the quantity says otherwise).
    pub error: f64,
    /// Tolerance on the error (None: reported only).
    pub tolerance: Option<f64>,
    /// Outcome.
    pub status: Status,
    /// Extra detail (why it failed, what stopped).
    pub detail: String,
}

impl Row {
    /// A compared row: relative error |value - reference| / |scale| against `tolerance`.
    pub fn compare(
        case: impl Into<String>,
        quantity: impl Into<String>,
        source: impl Into<String>,
        reference: f64,
        value: f64,
        scale: f64,
        tolerance: Option<f64>,
    ) -> Row {
        let error = (value - reference).abs() / scale.abs();
        Row::with_error(case, quantity, source, reference, value, error, tolerance)
    }

    /// A row with an error computed by the caller.
    pub fn with_error(
        case: impl Into<String>,
        quantity: impl Into<String>,
        source: impl Into<String>,
        reference: f64,
        value: f64,
        error: f64,
        tolerance: Option<f64>,
    ) -> Row {
        let status = match tolerance {
            None => Status::Info,
            Some(t) if error.is_finite() && error <= t => Status::Pass,
            Some(_) => Status::Fail,
        };
        Row {
            case: case.into(),
            quantity: quantity.into(),
            source: source.into(),
            reference,
            value,
            error,
            tolerance,
            status,
            detail: String::new(),
        }
    }

    /// A row for a case that could not run.
    pub fn failed(
        case: impl Into<String>,
        quantity: impl Into<String>,
        why: impl Into<String>,
    ) -> Row {
        Row {
            case: case.into(),
            quantity: quantity.into(),
            source: "-".into(),
            reference: f64::NAN,
            value: f64::NAN,
            error: f64::NAN,
            tolerance: None,
            status: Status::Fail,
            detail: why.into(),
        }
    }

    /// A row for a case whose feature does not exist yet.
    pub fn not_yet(
        case: impl Into<String>,
        quantity: impl Into<String>,
        why: impl Into<String>,
    ) -> Row {
        Row {
            status: Status::NotYet,
            ..Row::failed(case, quantity, why)
        }
    }

    /// Add a detail.
    pub fn detail(mut self, d: impl Into<String>) -> Row {
        self.detail = d.into();
        self
    }

    /// Whether this row makes the suite fail.
    pub fn is_failure(&self) -> bool {
        self.status == Status::Fail
    }
}

fn num(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else if x == 0.0 {
        "0".into()
    } else if x.abs() >= 1e-3 && x.abs() < 1e5 {
        format!("{x:.6}")
            .trim_end_matches('0')
            .trim_end_matches('.')
            .to_string()
    } else {
        format!("{x:.4e}")
    }
}

fn err(x: f64) -> String {
    if x.is_nan() {
        "-".into()
    } else {
        format!("{x:.2e}")
    }
}

/// The table's cells, header first.
pub fn cells(rows: &[Row]) -> Vec<[String; 8]> {
    let mut out = vec![[
        "case",
        "quantity",
        "reference source",
        "reference value",
        "palpa value",
        "error",
        "tolerance",
        "pass",
    ]
    .map(String::from)];
    for r in rows {
        out.push([
            r.case.clone(),
            r.quantity.clone(),
            r.source.clone(),
            num(r.reference),
            num(r.value),
            err(r.error),
            r.tolerance.map(err).unwrap_or_else(|| "-".into()),
            r.status.label().into(),
        ]);
    }
    out
}

/// The table as aligned plain text, with the details of failed and stopped rows below it.
pub fn text_table(rows: &[Row]) -> String {
    let c = cells(rows);
    let mut w = [0usize; 8];
    for r in &c {
        for k in 0..8 {
            w[k] = w[k].max(r[k].chars().count());
        }
    }
    let mut s = String::new();
    for (i, r) in c.iter().enumerate() {
        let line: Vec<String> = (0..8)
            .map(|k| format!("{:<width$}", r[k], width = w[k]))
            .collect();
        s.push_str(line.join("  ").trim_end());
        s.push('\n');
        if i == 0 {
            let total: usize = w.iter().sum::<usize>() + 2 * 7;
            s.push_str(&"-".repeat(total));
            s.push('\n');
        }
    }
    let details: Vec<&Row> = rows.iter().filter(|r| !r.detail.is_empty()).collect();
    if !details.is_empty() {
        s.push('\n');
        for r in details {
            let _ = writeln!(
                s,
                "[{}] {} / {}: {}",
                r.status.label(),
                r.case,
                r.quantity,
                r.detail
            );
        }
    }
    s
}

/// Counts of (pass, fail, info, named stop, not yet).
pub fn counts(rows: &[Row]) -> [usize; 5] {
    let mut n = [0; 5];
    for r in rows {
        n[match r.status {
            Status::Pass => 0,
            Status::Fail => 1,
            Status::Info => 2,
            Status::NamedStop => 3,
            Status::NotYet => 4,
        }] += 1;
    }
    n
}

/// One-line summary.
pub fn summary_line(rows: &[Row]) -> String {
    let n = counts(rows);
    format!(
        "{} rows: {} pass, {} fail, {} info, {} named stop, {} not yet",
        rows.len(),
        n[0],
        n[1],
        n[2],
        n[3],
        n[4]
    )
}

/// The Markdown report.
pub fn markdown(title: &str, out: &CaseOutput, plots: &[String], wall_seconds: f64) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# {title}\n");
    let _ = writeln!(
        s,
        "{} (wall time {wall_seconds:.1} s).\n",
        summary_line(&out.rows)
    );
    let c = cells(&out.rows);
    let esc = |x: &str| x.replace('|', "\\|");
    for (i, r) in c.iter().enumerate() {
        let line: Vec<String> = r.iter().map(|x| esc(x)).collect();
        let _ = writeln!(s, "| {} |", line.join(" | "));
        if i == 0 {
            let _ = writeln!(s, "|{}", "---|".repeat(8));
        }
    }
    let details: Vec<&Row> = out.rows.iter().filter(|r| !r.detail.is_empty()).collect();
    if !details.is_empty() {
        let _ = writeln!(s, "\n## Details\n");
        for r in details {
            let _ = writeln!(
                s,
                "- **{}** ({}), {}: {}",
                r.case,
                r.status.label(),
                r.quantity,
                r.detail
            );
        }
    }
    if !out.notes.is_empty() {
        let _ = writeln!(s, "\n## Notes\n");
        for n in &out.notes {
            let _ = writeln!(s, "- {n}");
        }
    }
    if !plots.is_empty() {
        let _ = writeln!(s, "\n## Plots\n");
        for p in plots {
            let _ = writeln!(s, "![{p}]({p})\n");
        }
    }
    s
}

pub use solver::output::atomic::write_atomic;
