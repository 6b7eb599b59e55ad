//! The files of one run in a campaign directory: `runs/<label>/`, its marker of a finished run
//! ([`DoneMarker`], `done.json`) and its samples ([`RunSamples`]: `probe.csv`,
//! `probe_stress.csv`, `history.csv`).

use crate::DONE_FILE;
use scene::palpation::read_probe;
use scene::run::RunStatus;
use serde::{Deserialize, Serialize};
use solver::output::atomic::write_atomic;
use solver::output::filter::{moving_average_at, FORCE_FILTER};
use solver::output::history::{column, read_history};
use std::path::{Path, PathBuf};

/// Directory of run `label` in campaign directory `out`.
pub fn run_dir(out: &Path, label: &str) -> PathBuf {
    out.join("runs").join(label)
}

/// The marker of a finished run (`done.json`), written last and atomically.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct DoneMarker {
    /// Run label.
    pub label: String,
    /// Run index in the campaign.
    pub index: usize,
    /// How the run ended (`completed`).
    pub status: RunStatus,
    /// Steps.
    pub steps: u64,
    /// Simulated time (s).
    pub simulated_time: f64,
    /// Wall time of the run (s).
    pub wall_seconds: f64,
    /// Worker threads of the run.
    pub threads: usize,
    /// Samples in `probe.csv`.
    pub samples: usize,
    /// When it finished (seconds since the Unix epoch).
    pub finished_unix: f64,
    /// Solver version.
    pub solver_version: String,
    /// Notes of the scene builder (e.g. the fingers' initial back-off).
    pub notes: Vec<String>,
}

/// The marker of a finished run in `dir`, if there is a readable one.
pub fn read_done(dir: &Path) -> Option<DoneMarker> {
    let s = std::fs::read_to_string(dir.join(DONE_FILE)).ok()?;
    serde_json::from_str(&s).ok()
}

/// Mark the run in `dir` finished.
pub fn write_done(dir: &Path, m: &DoneMarker) -> Result<(), String> {
    let s = serde_json::to_string_pretty(m).map_err(|e| e.to_string())?;
    write_atomic(&dir.join(DONE_FILE), s.as_bytes())
}

/// The samples of a finished run: `probe.csv` and `probe_stress.csv` of its hand `hand`.
#[derive(Clone, Debug, Default)]
pub struct RunSamples {
    /// Sample times (s).
    pub time: Vec<f64>,
    /// Hand force along the pressing direction (N), as probed at the sample time.
    pub force: Vec<f64>,
    /// The same force filtered: the centred [`FORCE_FILTER`] moving average of the run's
    /// `history.csv`, at the sample times ([`solver::output::filter`]).
    pub force_filtered: Vec<f64>,
    /// Indentation since first contact (m): `hand_depth`.
    pub depth: Vec<f64>,
    /// ROI element ids.
    pub elements: Vec<u32>,
    /// Maximum principal stress (Pa), per sample per ROI element.
    pub max_principal: Vec<Vec<f64>>,
    /// Cauchy stress (Pa), per sample per ROI element, xx, yy, zz, xy, yz, zx.
    pub tensors: Vec<Vec<[f64; 6]>>,
}

/// Read the samples of the finished run in `dir` (hand `hand`): `probe.csv`, `probe_stress.csv`
/// and, for the filtered force, `history.csv`.
pub fn read_run(dir: &Path) -> Result<RunSamples, String> {
    read_run_files(dir).map_err(|e| {
        format!(
            "{e}; the run's files are damaged: remove {} and continue with --resume to redo the run",
            dir.display()
        )
    })
}

fn read_run_files(dir: &Path) -> Result<RunSamples, String> {
    let hand = "hand";
    let p = read_probe(dir, hand)?;
    let (cols, rows) = read_history(&dir.join("probe.csv"))?;
    let depth = column(&cols, &rows, &format!("{hand}_depth")).ok_or_else(|| {
        format!(
            "{}: no column `{hand}_depth`",
            dir.join("probe.csv").display()
        )
    })?;
    let path = dir.join("history.csv");
    let (hcols, hrows) = read_history(&path)?;
    let need = |name: &str| {
        column(&hcols, &hrows, name)
            .ok_or_else(|| format!("{}: no column `{name}`", path.display()))
    };
    let force_filtered = moving_average_at(
        &need("time")?,
        &need(&format!("{hand}_reaction"))?,
        FORCE_FILTER,
        &p.time,
    );
    let path = dir.join("probe_stress.csv");
    let (tcols, trows) = read_history(&path)?;
    if trows.len() != p.time.len() {
        return Err(format!(
            "{}: {} rows, probe.csv has {}",
            path.display(),
            trows.len(),
            p.time.len()
        ));
    }
    let mut idx = Vec::with_capacity(p.elements.len());
    for e in &p.elements {
        let mut k = [0usize; 6];
        for (c, comp) in ["xx", "yy", "zz", "xy", "yz", "zx"].iter().enumerate() {
            let name = format!("e{e}_{comp}");
            k[c] = tcols
                .iter()
                .position(|x| *x == name)
                .ok_or_else(|| format!("{}: no column `{name}`", path.display()))?;
        }
        idx.push(k);
    }
    let tensors = trows
        .iter()
        .map(|row| idx.iter().map(|k| k.map(|c| row[c])).collect())
        .collect();
    Ok(RunSamples {
        time: p.time,
        force: p.force,
        force_filtered,
        depth,
        elements: p.elements,
        max_principal: p.stress,
        tensors,
    })
}
