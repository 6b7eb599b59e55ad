//! A run whose `probe.csv` was cut mid-row (a campaign killed while a file system lost its
//! tail): `--resume` reads it back as an error that names the run, the line and what to do,
//! never a panic (issue 29; the history reader itself is tested in scene/tests/integration/damaged_outputs.rs).

const PROBE: &str = "time,hand_reaction,hand_travel,hand_depth,e3,e4\n\
0.000000000e0,0.000000000e0,0.000000000e0,0.000000000e0,1.0e0,2.0e0\n\
5.000000000e-4,1.000000000e0,1.000000000e-3,1.000000000e-3,3.0e0,4.0e0\n\
1.000000000e-3,2.000000000e0,2.0000";

#[test]
fn cut_probe_is_an_error_naming_the_run_the_line_and_resume() {
    let tmp = tempfile::Builder::new()
        .prefix("palpa-test-cut-run-")
        .tempdir()
        .unwrap();
    let dir = tmp.path().join("P07");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("probe.csv"), PROBE).unwrap();
    let e = campaign::read_run(&dir).unwrap_err();
    assert!(
        e.contains("P07") && e.contains("line 4") && e.contains("--resume"),
        "{e}"
    );
}
