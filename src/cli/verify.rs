//! `palpa verify [--hard] [--out DIR]`: run the verification suite, print the table, write the
//! Markdown report and the plots, and fail if any row fails.

use std::path::Path;

/// Run the suite.
pub fn verify(hard: bool, out: &Path) -> Result<(), String> {
    eprintln!(
        "palpa verify{}: running {} ...",
        if hard { " --hard" } else { "" },
        if hard {
            "the hard-case suite"
        } else {
            "the reference problems and closed forms"
        }
    );
    let v = verification::verify(hard, out, |name, secs| eprintln!("  {name}: {secs:.1} s"))?;
    println!("{}", v.table);
    println!("{}", verification::report::summary_line(&v.output.rows));
    println!(
        "wall time {:.1} s; wrote {} into {}",
        v.seconds,
        v.files.join(", "),
        out.display()
    );
    for w in &v.warnings {
        eprintln!("warning: {w}");
    }
    match v.failures() {
        0 => Ok(()),
        n => Err(format!("{n} verification row(s) failed")),
    }
}
