//! `palpa run deck.k`, `palpa check deck.k` and `palpa export --lsdyna` from the command line:
//! exit codes, units, and where the messages go.

use std::path::Path;
use std::process::Command;

fn palpa(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_palpa"))
        .args(args)
        .output()
        .unwrap();
    let so = String::from_utf8_lossy(&out.stdout).into_owned();
    let se = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!se.contains("panicked"), "panic: {se}");
    (out.status.success(), so, se)
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn a_deck_runs_with_units_and_is_refused_without() {
    let deck = root().join("scenes/decks/compression-elastic.k");
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("out");
    let (ok, _, err) = palpa(&[
        "run",
        deck.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(!ok);
    assert!(
        err.contains("compression-elastic.k") && err.contains("--units"),
        "{err}"
    );
    let (ok, so, err) = palpa(&[
        "run",
        deck.to_str().unwrap(),
        "--units",
        "kg-mm-ms",
        "--out",
        out.to_str().unwrap(),
        "--quiet",
    ]);
    assert!(ok, "{so}\n{err}");
    assert!(so.contains("units kg-mm-ms (from --units)"), "{so}");
    let h = std::fs::read_to_string(out.join("history.csv")).unwrap();
    assert!(
        h.starts_with("time,") && h.contains("zmax_reaction_z"),
        "{h}"
    );
    let (ok, _, err) = palpa(&["check", deck.to_str().unwrap(), "--units", "kg-mm-furlong"]);
    assert!(
        !ok && err.contains("--units") && err.contains("furlong"),
        "{err}"
    );
}

#[test]
fn check_lists_every_problem_of_a_deck() {
    let tmp = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(root().join("scenes/decks/compression-ogden.k")).unwrap();
    let bad = src
        .replace(
            "*BOUNDARY_SPC_SET",
            "*CONSTRAINED_GLOBAL\n*BOUNDARY_SPC_SET",
        )
        .replace(
            "*DATABASE_GLSTAT",
            "*DATABASE_NODOUT\n       0.1\n*DATABASE_GLSTAT",
        );
    let p = tmp.path().join("bad.k");
    std::fs::write(&p, bad).unwrap();
    std::fs::copy(
        root().join("scenes/decks/block-mesh.k"),
        tmp.path().join("block-mesh.k"),
    )
    .unwrap();
    let (ok, so, err) = palpa(&["check", p.to_str().unwrap()]);
    assert!(!ok);
    assert!(
        so.contains("error: ") && so.contains("*CONSTRAINED_GLOBAL"),
        "{so}"
    );
    assert!(
        so.contains("warning: ") && so.contains("*DATABASE_NODOUT"),
        "{so}"
    );
    assert!(err.contains("bad.k") && err.contains("1 error(s)"), "{err}");
}

#[test]
fn export_writes_a_deck_that_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let deck = tmp.path().join("block.k");
    let (ok, so, err) = palpa(&[
        "export",
        "--lsdyna",
        root()
            .join("scenes/compression-block.toml")
            .to_str()
            .unwrap(),
        "--out",
        deck.to_str().unwrap(),
        "--units",
        "t-mm-s",
    ]);
    assert!(ok, "{so}\n{err}");
    assert!(so.contains("neo-Hookean"), "{so}");
    let text = std::fs::read_to_string(&deck).unwrap();
    assert!(text.starts_with("*KEYWORD LONG=Y") && text.contains("*CONTROL_UNITS"));
    let (ok, so, err) = palpa(&["check", deck.to_str().unwrap(), "--ignore-palpa-comments"]);
    assert!(ok, "{so}\n{err}");
    assert!(so.contains("law ogden"), "{so}");
    let (ok, so, _) = palpa(&["check", deck.to_str().unwrap()]);
    assert!(ok && so.contains("law neo_hookean"), "{so}");
    let (ok, _, err) = palpa(&[
        "export",
        "--lsdyna",
        root()
            .join("scenes/compression-block.toml")
            .to_str()
            .unwrap(),
        "--out",
        deck.to_str().unwrap(),
        "--segments",
        "7",
    ]);
    assert!(!ok && err.contains("--segments"), "{err}");
}
