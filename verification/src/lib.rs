//! Verification of palpa against reference solvers and closed forms.
//!
//! Each case is a function that runs palpa on a reference problem and returns [`Row`]s: a case
//! name, the quantity compared, where the reference comes from, the reference value, palpa's
//! value, the error, the tolerance the case states and whether it passed. The references are
//! the committed outputs of the Python scripts in `verification/python/` (scikit-fem and
//! FEniCSx, in `verification/data/*.json`) and closed forms written out in each case's module
//! doc, so `cargo test` needs no Python.
//!
//! - [`cases::patch`]: distorted-hexahedron patch tests vs scikit-fem and FEniCSx.
//! - [`cases::block`]: the roller compression block (exact) and the clamped block (FEniCSx Q1/Q2).
//! - [`cases::cantilever`]: tip deflection vs scikit-fem Q1 and Timoshenko beam theory.
//! - [`cases::closed`]: Ogden, Prony, plasticity, wave speed, free vibration, Hertz.
//! - [`hard`]: the hard-case suite (`palpa verify --hard`).
//! - [`study`]: accuracy against cost (`palpa study`), with its Hertz block ([`study_hertz`])
//!   and its rows ([`study_row`]).
//!
//! [`run_suite`] runs the default suite; [`report`] prints the table and writes the Markdown
//! report and the convergence plots.
#![warn(missing_docs)]

pub mod cases;
pub mod data;
pub mod hard;
pub mod plot;
pub mod quasi;
pub mod report;
pub mod study;
pub mod study_hertz;
pub mod study_paper;
pub mod study_paper_record;
pub mod study_paper_report;
pub mod study_row;

pub use report::{Row, Status};

/// Extra series a case hands to the report for plotting.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// File stem of the plot (`block_convergence` -> `block_convergence.png`).
    pub plot: String,
    /// Plot title.
    pub title: String,
    /// Axis labels (x, y).
    pub axes: (String, String),
    /// Log-log axes.
    pub log: bool,
    /// Named curves of (x, y) points.
    pub curves: Vec<(String, Vec<(f64, f64)>)>,
}

/// What a case returns: table rows and plot series.
#[derive(Clone, Debug, Default)]
pub struct CaseOutput {
    /// Table rows.
    pub rows: Vec<Row>,
    /// Plot series.
    pub series: Vec<Series>,
    /// Free-text notes for the report (observed rates, explanations).
    pub notes: Vec<String>,
}

impl CaseOutput {
    /// Append another output.
    pub fn extend(&mut self, other: CaseOutput) {
        self.rows.extend(other.rows);
        self.series.extend(other.series);
        self.notes.extend(other.notes);
    }
}

/// A named case of the suite.
pub struct Case {
    /// Name shown while running.
    pub name: &'static str,
    /// The case.
    pub run: fn() -> CaseOutput,
}

/// The default suite, in report order.
pub fn default_suite() -> Vec<Case> {
    vec![
        Case {
            name: "patch tests",
            run: cases::patch::run,
        },
        Case {
            name: "roller block",
            run: cases::block::roller,
        },
        Case {
            name: "clamped block",
            run: cases::block::clamped,
        },
        Case {
            name: "cantilever",
            run: cases::cantilever::run,
        },
        Case {
            name: "closed forms (laws)",
            run: cases::closed::laws,
        },
        Case {
            name: "wave speed",
            run: cases::closed::wave,
        },
        Case {
            name: "free vibration",
            run: cases::closed::vibration,
        },
        Case {
            name: "Hertz contact",
            run: cases::closed::hertz,
        },
    ]
}

/// Run a list of cases, calling `progress` with each case's name and wall time (s).
pub fn run_cases(cases: &[Case], mut progress: impl FnMut(&str, f64)) -> CaseOutput {
    let mut out = CaseOutput::default();
    for c in cases {
        let t0 = std::time::Instant::now();
        let o = (c.run)();
        progress(c.name, t0.elapsed().as_secs_f64());
        out.extend(o);
    }
    out
}

/// Everything `palpa verify` produces.
pub struct Verification {
    /// Rows, series and notes.
    pub output: CaseOutput,
    /// The printed table.
    pub table: String,
    /// Files written (report and plots), relative to the output directory.
    pub files: Vec<String>,
    /// Problems writing plots (the suite still counts).
    pub warnings: Vec<String>,
    /// Wall time (s).
    pub seconds: f64,
}

impl Verification {
    /// Rows that failed.
    pub fn failures(&self) -> usize {
        self.output.rows.iter().filter(|r| r.is_failure()).count()
    }
}

/// Run the default suite (or the hard-case suite), write `report.md` (or `hard-report.md`)
/// and the plots into `out`, and return the table.
pub fn verify(
    hard: bool,
    out: &std::path::Path,
    progress: impl FnMut(&str, f64),
) -> Result<Verification, String> {
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create `{}`: {e}", out.display()))?;
    let t0 = std::time::Instant::now();
    let cases = if hard {
        vec![Case {
            name: "hard cases",
            run: hard::run,
        }]
    } else {
        default_suite()
    };
    let output = run_cases(&cases, progress);
    let seconds = t0.elapsed().as_secs_f64();
    let mut files = Vec::new();
    let mut warnings = Vec::new();
    for s in &output.series {
        match plot::draw(s, out) {
            Ok(f) => files.push(f),
            Err(e) => warnings.push(e),
        }
    }
    let (title, name) = if hard {
        ("palpa verify --hard: hard-case suite", "hard-report.md")
    } else {
        (
            "palpa verify: reference problems and closed forms",
            "report.md",
        )
    };
    let md = report::markdown(title, &output, &files, seconds);
    report::write_atomic(&out.join(name), md.as_bytes())?;
    files.insert(0, name.to_string());
    let table = report::text_table(&output.rows);
    Ok(Verification {
        output,
        table,
        files,
        warnings,
        seconds,
    })
}
