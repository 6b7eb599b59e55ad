//! Running a campaign's runs: `jobs` side by side, each on its own rayon pool of `threads`
//! workers, each run from scratch into `runs/<label>/` and marked finished by `done.json` at the
//! end. On 2 cores two runs side by side with one thread each beat one run at a time with two
//! threads; the solver is deterministic across thread counts, so the results are identical
//! either way. The caller watches through [`RunEvent`]s (the CLI draws its progress bar from
//! them) and may stop the runs with its stop flag.

use crate::plan::{Campaign, PlannedRun};
use crate::run_files::{read_run, run_dir, write_done, DoneMarker};
use phantom::Phantom;
use scene::run::{run_scene, RunStatus};
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

/// What happened to a run, as [`execute`] reports it (from any of its worker threads).
pub enum RunEvent<'a> {
    /// Job `slot` started `run`.
    Started {
        /// The job.
        slot: usize,
        /// The run.
        run: &'a PlannedRun,
    },
    /// Job `slot`'s run reached simulated time `time` (s).
    Progress {
        /// The job.
        slot: usize,
        /// The run.
        run: &'a PlannedRun,
        /// Its simulated time (s).
        time: f64,
    },
    /// Job `slot`'s run finished.
    Finished {
        /// The job.
        slot: usize,
        /// The run.
        run: &'a PlannedRun,
        /// Its marker.
        marker: &'a DoneMarker,
    },
    /// Job `slot`'s run was ended by the stop flag (it stays unfinished).
    Stopped {
        /// The job.
        slot: usize,
        /// The run.
        run: &'a PlannedRun,
    },
    /// Job `slot`'s run failed.
    Failed {
        /// The job.
        slot: usize,
        /// The run.
        run: &'a PlannedRun,
        /// The error.
        error: &'a str,
    },
}

/// How many runs go side by side, and the worker threads of each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Parallelism {
    /// Runs side by side.
    pub jobs: usize,
    /// Worker threads per run.
    pub threads: usize,
}

impl Parallelism {
    /// The given `jobs` and `threads`, or by default as many jobs as `cores` (at most one a run
    /// to do) and the cores split between them.
    pub fn choose(
        jobs: Option<usize>,
        threads: Option<usize>,
        runs: usize,
        cores: usize,
    ) -> Parallelism {
        let jobs = jobs.unwrap_or(cores).min(runs).max(1);
        let threads = threads.unwrap_or((cores / jobs).max(1));
        Parallelism { jobs, threads }
    }
}

/// What [`execute`] did.
pub struct Report {
    /// Runs finished.
    pub finished: usize,
    /// Runs that failed, with their errors, by label.
    pub failed: Vec<(String, String)>,
    /// Whether the stop flag ended the invocation.
    pub stopped: bool,
    /// Wall time of the runs, summed over the jobs (s).
    pub run_seconds: f64,
}

/// Run `todo`, `jobs` at a time with `threads` each, reusing `phantom`, until done or `stop`.
/// `on` sees every run start, progress and end (finished, stopped or failed; the events of
/// one job in order, those of different jobs interleaved).
#[allow(clippy::too_many_arguments)]
pub fn execute(
    c: &Campaign,
    todo: &[&PlannedRun],
    out: &Path,
    phantom: &Phantom,
    jobs: usize,
    threads: usize,
    stop: &AtomicBool,
    on: &(dyn Fn(RunEvent) + Sync),
) -> Result<Report, String> {
    let next = AtomicUsize::new(0);
    let finished = AtomicUsize::new(0);
    let failed: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());
    let run_seconds = Mutex::new(0.0f64);
    let worker = |slot: usize| -> Result<(), String> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| e.to_string())?;
        loop {
            if stop.load(Ordering::SeqCst) {
                break;
            }
            let k = next.fetch_add(1, Ordering::SeqCst);
            let Some(&run) = todo.get(k) else { break };
            on(RunEvent::Started { slot, run });
            let t0 = Instant::now();
            let res = pool.install(|| {
                run_one(c, run, out, phantom, stop, &mut |time| {
                    on(RunEvent::Progress { slot, run, time })
                })
            });
            *run_seconds.lock().unwrap() += t0.elapsed().as_secs_f64();
            match res {
                Ok(marker) => {
                    finished.fetch_add(1, Ordering::SeqCst);
                    on(RunEvent::Finished {
                        slot,
                        run,
                        marker: &marker,
                    });
                }
                Err(_) if stop.load(Ordering::SeqCst) => on(RunEvent::Stopped { slot, run }),
                Err(error) => {
                    on(RunEvent::Failed {
                        slot,
                        run,
                        error: &error,
                    });
                    failed.lock().unwrap().push((run.label.clone(), error));
                }
            }
        }
        Ok(())
    };
    let results: Vec<Result<(), String>> = std::thread::scope(|sc| {
        let handles: Vec<_> = (0..jobs)
            .map(|j| {
                let w = &worker;
                sc.spawn(move || w(j))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err("a campaign worker panicked".into()))
            })
            .collect()
    });
    for r in results {
        r?;
    }
    let mut failed = failed.into_inner().unwrap();
    failed.sort();
    Ok(Report {
        finished: finished.into_inner(),
        failed,
        stopped: stop.load(Ordering::SeqCst),
        run_seconds: run_seconds.into_inner().unwrap(),
    })
}

fn now_unix() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

/// One run, from scratch, into `runs/<label>/`, marked finished by `done.json` at the end.
pub fn run_one(
    c: &Campaign,
    r: &PlannedRun,
    out: &Path,
    phantom: &Phantom,
    stop: &AtomicBool,
    progress: &mut dyn FnMut(f64),
) -> Result<DoneMarker, String> {
    let dir = run_dir(out, &r.label);
    if dir.exists() {
        std::fs::remove_dir_all(&dir)
            .map_err(|e| format!("{}: cannot clear the unfinished run: {e}", dir.display()))?;
    }
    let mut scene = c.build_run_scene(r, &dir, phantom)?;
    let notes = scene.notes.clone();
    let (summary, err) = run_scene(&mut scene, &dir, stop, |p| progress(p.sim.time));
    if let Some(e) = err {
        return Err(e);
    }
    if summary.status != RunStatus::Completed {
        return Err(format!("run {}", summary.status));
    }
    let samples = read_run(&dir)?;
    let m = DoneMarker {
        label: r.label.clone(),
        index: r.index,
        status: summary.status,
        steps: summary.steps,
        simulated_time: summary.time,
        wall_seconds: summary.wall_seconds,
        threads: summary.threads,
        samples: samples.time.len(),
        finished_unix: now_unix(),
        solver_version: env!("CARGO_PKG_VERSION").into(),
        notes,
    };
    write_done(&dir, &m)?;
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::Parallelism;

    /// On 2 cores: two runs side by side with one thread each; one run left gets both cores;
    /// what is given is kept (at most one job a run).
    #[test]
    fn parallelism_splits_the_cores_between_the_runs() {
        let p = |j, t, n, c| {
            let p = Parallelism::choose(j, t, n, c);
            (p.jobs, p.threads)
        };
        assert_eq!(p(None, None, 28, 2), (2, 1));
        assert_eq!(p(None, None, 1, 2), (1, 2));
        assert_eq!(p(None, None, 0, 2), (1, 2));
        assert_eq!(p(Some(4), None, 3, 16), (3, 5));
        assert_eq!(p(Some(1), Some(2), 28, 2), (1, 2));
    }
}
