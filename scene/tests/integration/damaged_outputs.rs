//! Output files and output clocks that broke on real faults (issue 29):
//! - a `probe.csv` cut mid-row (a campaign killed while a file system lost its tail) made
//!   `--resume` panic with an index out of bounds in `read_probe`: reading it back is now an
//!   error naming the file and the line, and the campaign's reader says how to redo the run (campaign/tests/damaged_run.rs);
//! - the output clock of the time loop added the interval until it passed the current time, so
//!   one step far longer than the interval (a huge stable step) looped for as many intervals as
//!   the step spanned, or for ever once `next + dt` rounded back to `next`.

use crate::common;
use scene::run::{next_output_time, run_scene};
use solver::output::history::read_history;
use std::sync::atomic::AtomicBool;

const PROBE: &str = "time,hand_reaction,hand_travel,hand_depth,e3,e4\n\
0.000000000e0,0.000000000e0,0.000000000e0,0.000000000e0,1.0e0,2.0e0\n\
5.000000000e-4,1.000000000e0,1.000000000e-3,1.000000000e-3,3.0e0,4.0e0\n\
1.000000000e-3,2.000000000e0,2.0000";

#[test]
fn probe_csv_cut_mid_row_is_an_error_naming_the_line() {
    let tmp = common::tmp_dir("cut-probe");
    let dir = tmp.path().join("P07");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("probe.csv"), PROBE).unwrap();
    let e = read_history(&dir.join("probe.csv")).unwrap_err();
    assert!(
        e.contains("probe.csv")
            && e.contains("line 4")
            && e.contains("3 values")
            && e.contains("6 columns"),
        "{e}"
    );
    // The reader the campaign uses on --resume: an error, no panic, naming what to do.
    let e = scene::palpation::read_probe(&dir, "hand").unwrap_err();
    assert!(e.contains("line 4"), "{e}");
    // (The campaign's own reader of a run says how to redo it: campaign/tests/damaged_run.rs.)
    // A value that is not a number names its line too.
    std::fs::write(dir.join("probe.csv"), PROBE.replace("3.0e0", "3.0x")).unwrap();
    let e = read_history(&dir.join("probe.csv")).unwrap_err();
    assert!(e.contains("line 3") && e.contains("`3.0x`"), "{e}");
    // The intact rows still read.
    let whole = PROBE.rsplit_once('\n').unwrap().0;
    std::fs::write(dir.join("probe.csv"), whole).unwrap();
    let (cols, rows) = read_history(&dir.join("probe.csv")).unwrap();
    assert_eq!((cols.len(), rows.len()), (6, 2));
}

#[test]
fn huge_step_past_end_time_does_not_stall_the_output_clock() {
    // The old clock: `next += dt` while `next <= t`. With t = 1e149 s and dt = 1 us it would
    // never end (1e-6 is lost against 1e149); the new one jumps in one step.
    let cases = [
        (1e-6, 1e-6, 1e149),
        (0.0, 2e-12, 5e-6),
        (3e-3, 1e-3, 3e-3),
        (1e-3, 1e-3, 0.0),
        (0.5, 0.1, 0.55),
    ];
    for (next, dt, t) in cases {
        let n = next_output_time(next, dt, t);
        assert!(n > t, "next {next}, dt {dt}, t {t}: got {n}");
        if next > t {
            assert_eq!(n, next);
        } else {
            // the first grid time after t, when the grid resolves it
            assert!(
                n - dt <= t * (1.0 + 1e-12) || n == t + dt,
                "{next} {dt} {t}: {n}"
            );
        }
    }
    // dt = 0 means a row every step: the clock stays put.
    assert_eq!(next_output_time(0.0, 0.0, 1.0), 0.0);
}

#[test]
fn a_run_shorter_than_one_stable_step_ends() {
    // end_time 1 ns against a stable step of microseconds: one step passes the end time and the
    // loop must stop there with the final row written.
    let src = r#"
[run]
end_time = "1 ns"
[mesh]
generator = "box"
size = ["10 mm", "10 mm", "10 mm"]
divisions = [2, 2, 2]
[materials.rubber]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "1 MPa"
poisson_ratio = 0.3
[[part]]
name = "body"
material = "rubber"
[[boundary]]
nodes = "zmin"
fix = ["all"]
[output]
history_interval = "1e-15 s"
interval = "1e-13 s"
"#;
    let mut scene = common::scene_from_str(src);
    let tmp = common::tmp_dir("one-step");
    let (summary, err) = run_scene(&mut scene, tmp.path(), &AtomicBool::new(false), |_| {});
    assert!(err.is_none(), "{err:?}");
    assert!(summary.time >= 1e-9 * (1.0 - 1e-12), "{}", summary.time);
    let (_, rows) = read_history(&tmp.path().join("history.csv")).unwrap();
    assert!(rows.len() <= 3, "{} rows", rows.len());
}
