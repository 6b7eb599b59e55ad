//! Loading what `palpa run` and `palpa check` are given: a TOML scene, or an LS-DYNA keyword
//! deck (`.k`, `.key`, `.dyn`) read by the `lsdyna` crate with the unit system the user states.

use scene::{load_scene, Scene};
use std::path::Path;

/// How to read a keyword deck (ignored for a TOML scene).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct DeckArgs {
    /// The unit system of an LS-DYNA deck (mass-length-time), e.g. kg-mm-ms, t-mm-s, kg-m-s;
    /// needed unless the deck has *CONTROL_UNITS.
    #[arg(long)]
    pub units: Option<String>,
    /// Read an LS-DYNA deck as LS-DYNA does: skip the `$palpa:` comments that
    /// `palpa export --lsdyna` writes (exact shapes, curves and laws).
    #[arg(long)]
    pub ignore_palpa_comments: bool,
}

/// A loaded scene and, for a deck, what reading it found.
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// The deck's report (units, keywords, warnings, mapping).
    pub report: Option<lsdyna::Report>,
}

fn options(args: &DeckArgs) -> Result<lsdyna::ReadOptions, String> {
    Ok(lsdyna::ReadOptions {
        units: match &args.units {
            Some(u) => Some(lsdyna::Units::parse(u).map_err(|e| format!("--units: {e}"))?),
            None => None,
        },
        ignore_palpa_comments: args.ignore_palpa_comments,
    })
}

/// Load a scene file or a deck.
pub fn load(path: &Path, args: &DeckArgs) -> Result<Loaded, String> {
    if lsdyna::is_deck(path) {
        let (scene, report) = lsdyna::load_deck(path, &options(args)?).map_err(|e| {
            let mut s = e.to_string();
            if !e.warnings.is_empty() {
                s.push_str(&format!(
                    "\n(and {} warning(s); `palpa check {}` lists them)",
                    e.warnings.len(),
                    path.display()
                ));
            }
            s
        })?;
        Ok(Loaded {
            scene,
            report: Some(report),
        })
    } else {
        if args.units.is_some() {
            return Err(format!(
                "--units applies to LS-DYNA decks (.k, .key, .dyn); {} is a scene, whose quantities carry their units",
                path.display()
            ));
        }
        Ok(Loaded {
            scene: load_scene(path)?,
            report: None,
        })
    }
}

/// Print a deck's report (for `check`, or the warnings before a run).
pub fn print_report(r: &lsdyna::Report, full: bool) {
    if full {
        println!(
            "  files: {}",
            r.files
                .iter()
                .map(|f| f.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        );
        println!("  units: {}", r.units);
        let kws: Vec<String> = r
            .counts
            .iter()
            .map(|(k, n)| {
                if *n > 1 {
                    format!("*{k} x{n}")
                } else {
                    format!("*{k}")
                }
            })
            .collect();
        println!("  keywords: {}", kws.join(", "));
        for m in &r.mapping {
            println!("  {m}");
        }
    }
    for w in &r.warnings {
        println!("  warning: {w}");
    }
}

/// Check a deck that does not load: list every problem.
pub fn check_failed_deck(path: &Path, args: &DeckArgs) -> Option<String> {
    let opts = options(args).ok()?;
    match lsdyna::read_deck(path, &opts) {
        Err(e) => {
            for w in &e.warnings {
                println!("  warning: {w}");
            }
            for x in &e.errors {
                println!("  error: {x}");
            }
            Some(format!(
                "{}: {} error(s), {} warning(s); palpa cannot run this deck",
                path.display(),
                e.errors.len(),
                e.warnings.len()
            ))
        }
        Ok(_) => None,
    }
}
