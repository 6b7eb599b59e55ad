//! The files of one run in a campaign directory: `runs/<label>/`, its marker of a finished run
//! ([`DoneMarker`], `done.json`) and its samples ([`RunSamples`]: `probe.csv`,
//! `probe_stress.csv`, `history.csv`); and the finished runs in `runs/` that a plan does not
//! name ([`stray_runs`]), which a campaign does not reuse.

use crate::DONE_FILE;
use scene::palpation::read_probe;
use scene::run::RunStatus;
use serde::{Deserialize, Serialize};
use solver::output::atomic::write_atomic;
use solver::output::filter::{moving_average_at, FORCE_FILTER};
use solver::output::history::{column, read_history};
use std::path::{Path, PathBuf};

/// Directory of the runs in campaign directory `out`.
pub fn runs_dir(out: &Path) -> PathBuf {
    out.join("runs")
}

/// Directory of run `label` in campaign directory `out`.
pub fn run_dir(out: &Path, label: &str) -> PathBuf {
    runs_dir(out).join(label)
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

/// The finished runs in `out/runs/` whose label is not among `labels`, sorted: runs a campaign
/// does not reuse. A design's labels are padded to the digits of its n (S01..S75, S001..S200),
/// so runs copied from a smaller design to extend it across a power of ten are among them, as
/// are the runs of a location since removed from the campaign file.
pub fn stray_runs<'a>(out: &Path, labels: impl IntoIterator<Item = &'a str>) -> Vec<String> {
    let known: std::collections::HashSet<&str> = labels.into_iter().collect();
    let Ok(entries) = std::fs::read_dir(runs_dir(out)) else {
        return Vec::new();
    };
    let mut stray: Vec<String> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|l| !known.contains(l.as_str()) && is_finished(out, l))
        .collect();
    stray.sort();
    stray
}

/// Whether run `label` of the campaign in `out` is finished (has a readable `done.json`).
pub fn is_finished(out: &Path, label: &str) -> bool {
    read_done(&run_dir(out, label)).is_some()
}

/// Remove the run `label` from `out`: its directory goes, so that nothing (the dataset, a
/// later `--resume`, `palpa front`) takes it for finished; for a copied run that is not the
/// palpation planned for it.
pub fn discard_run(out: &Path, label: &str) -> Result<(), String> {
    let dir = run_dir(out, label);
    std::fs::remove_dir_all(&dir).map_err(|e| format!("{}: cannot remove: {e}", dir.display()))
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

#[cfg(test)]
mod tests {
    use super::{run_dir, stray_runs, write_done, DoneMarker};
    use scene::run::RunStatus;

    fn finish(out: &std::path::Path, label: &str) {
        let dir = run_dir(out, label);
        std::fs::create_dir_all(&dir).unwrap();
        let m = DoneMarker {
            label: label.into(),
            index: 0,
            status: RunStatus::Completed,
            steps: 1,
            simulated_time: 0.0,
            wall_seconds: 0.0,
            threads: 1,
            samples: 0,
            finished_unix: 0.0,
            solver_version: String::new(),
            notes: Vec::new(),
        };
        write_done(&dir, &m).unwrap();
    }

    /// Runs copied from a 75-point design (S01..) into a 200-point one (S001..) are named as
    /// not reused; an unfinished stray run and the plan's own runs are not.
    #[test]
    fn stray_runs_are_the_finished_runs_the_plan_does_not_name() {
        let t = tempfile::tempdir().unwrap();
        assert!(stray_runs(t.path(), ["S001"]).is_empty());
        for l in ["S10", "S01", "S02", "S001", "A"] {
            finish(t.path(), l);
        }
        std::fs::create_dir_all(run_dir(t.path(), "S03")).unwrap();
        assert_eq!(
            stray_runs(t.path(), ["S001", "S002", "A"]),
            vec!["S01".to_string(), "S02".to_string(), "S10".to_string()]
        );
    }
}
