//! `palpa export --lsdyna SCENE --out deck.k`: write a scene, as palpa would run it, as an
//! LS-DYNA keyword deck (see the `lsdyna` crate's `export` module and docs/lsdyna.md).

use super::input::{load, DeckArgs};
use solver::output::atomic::write_atomic;
use std::path::PathBuf;

/// Options of `palpa export`.
#[derive(clap::Args, Debug)]
pub struct ExportArgs {
    /// Write an LS-DYNA keyword deck (the only format so far).
    #[arg(long, required = true)]
    pub lsdyna: bool,
    /// The scene to write (TOML, or a deck to rewrite).
    pub scene: PathBuf,
    /// The deck to write.
    #[arg(long)]
    pub out: PathBuf,
    /// The deck's unit system (mass-length-time).
    #[arg(long, default_value = "kg-mm-ms")]
    pub units: String,
    /// Field widths: long (20 columns, `*KEYWORD LONG=Y`: 15-17 significant digits) or standard
    /// (8/10/16 columns: about 6 significant digits in 10 columns).
    #[arg(long, default_value = "long")]
    pub format: String,
    /// Points of a tabulated smooth-step curve.
    #[arg(long, default_value_t = 2001)]
    pub curve_points: usize,
    /// Segments around a circle of a meshed indenter (a multiple of 8).
    #[arg(long, default_value_t = 64)]
    pub segments: usize,
    /// Units of the input when it is itself a deck without *CONTROL_UNITS.
    #[arg(long)]
    pub input_units: Option<String>,
}

/// Run `palpa export`.
pub fn export(a: &ExportArgs) -> Result<(), String> {
    let units = lsdyna::Units::parse(&a.units).map_err(|e| format!("--units: {e}"))?;
    let long = match a.format.as_str() {
        "long" => true,
        "standard" => false,
        o => return Err(format!("--format: `{o}` is not long or standard")),
    };
    if a.segments < 8 || a.segments % 8 != 0 {
        return Err(format!(
            "--segments: {} is not a multiple of 8 (at least 8)",
            a.segments
        ));
    }
    if a.curve_points < 3 {
        return Err("--curve-points: at least 3".into());
    }
    let loaded = load(
        &a.scene,
        &DeckArgs {
            units: a.input_units.clone(),
            ignore_palpa_comments: false,
        },
    )?;
    let opts = lsdyna::export::ExportOptions {
        units,
        long,
        curve_points: a.curve_points,
        segments: a.segments,
        source: a.scene.display().to_string(),
    };
    let e = lsdyna::export::export(&loaded.scene, &opts)
        .map_err(|m| format!("{}: cannot export: {m}", a.scene.display()))?;
    if let Some(dir) = a.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|err| format!("{}: cannot create the directory: {err}", dir.display()))?;
    }
    write_atomic(&a.out, e.text.as_bytes())?;
    println!(
        "wrote {} ({} lines, units {}, {} format)",
        a.out.display(),
        e.text.lines().count(),
        opts.units.name,
        if long { "long" } else { "standard" }
    );
    println!(
        "  numbers: {} written, {} exactly (to the bit of palpa's SI value); {} rounded to fit their field (largest relative rounding {:.1e})",
        e.values,
        e.values - e.inexact,
        e.inexact,
        e.max_rounding
    );
    for n in &e.notes {
        println!("  note: {n}");
    }
    Ok(())
}
