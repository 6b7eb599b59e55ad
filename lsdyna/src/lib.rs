//! LS-DYNA keyword decks for palpa: `palpa run deck.k` and `palpa check deck.k` read a deck
//! into a palpa scene, `palpa export --lsdyna` writes a scene as a deck that LS-DYNA or the
//! OpenRadioss starter reads.
//!
//! Reading goes in three steps, each its own module:
//! - [`lex`]: the keyword format (fixed columns, free format, long and i10 formats, `$`
//!   comments, `*INCLUDE`), and [`params`]: `*PARAMETER` values for `&NAME` fields;
//! - [`keywords`]: the keywords palpa knows, parsed into plain records in deck units, and the
//!   verdict (warning or error) on every other keyword;
//! - [`scene`]: the records turned into a palpa scene in SI, with the unit system the user
//!   states ([`units`]).
//!
//! [`export`] writes the other way, from the scene palpa would run. Where a palpa scene has no
//! exact LS-DYNA equivalent (an analytic finger, a smooth-step curve, a neo-Hookean law), the
//! deck carries LS-DYNA's nearest form and a `$palpa:` comment with palpa's own
//! ([`annotate`]); palpa reads the comment back after checking it against the LS-DYNA data.
//!
//! The supported subset and the mapping are documented in `docs/lsdyna.md`.

pub mod annotate;
pub mod card;
pub mod export;
pub mod keywords;
pub mod lex;
pub mod params;
pub mod scene;
pub mod units;

pub use scene::{DeckError, ReadOptions, Report};
pub use units::Units;

use ::scene::def::SceneDef;
use ::scene::Scene;
use std::path::Path;

/// Whether a file name looks like a keyword deck (`.k`, `.key`, `.dyn`, `.kw`).
pub fn is_deck(path: &Path) -> bool {
    matches!(
        path.extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .as_deref(),
        Some("k" | "key" | "dyn" | "kw" | "lsdyna")
    )
}

/// Read a deck (and its includes) into a resolved scene.
pub fn read_deck(path: &Path, opts: &ReadOptions) -> Result<(SceneDef, Report), DeckError> {
    let lexed = lex::read(path)
        .and_then(|mut l| params::expand(&mut l).map(|()| l))
        .map_err(|e| DeckError {
            errors: vec![e],
            warnings: Vec::new(),
        })?;
    let deck = keywords::parse(&lexed);
    scene::to_scene(&deck, path, &lexed.files, opts)
}

/// Read a deck and assemble it into a runnable scene.
pub fn load_deck(path: &Path, opts: &ReadOptions) -> Result<(Scene, Report), DeckError> {
    let (def, report) = read_deck(path, opts)?;
    let scene = ::scene::def::assemble(def).map_err(|e| DeckError {
        errors: vec![e],
        warnings: report.warnings.clone(),
    })?;
    Ok((scene, report))
}
