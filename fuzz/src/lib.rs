//! Fuzz harnesses for palpa's input parsers (docs/fuzzing.md). One function per input palpa
//! reads; each binary in `src/bin/` feeds afl.rs's input to one of them, and
//! `tests/corpus.rs` replays the committed corpus through them in a plain `cargo test`.
//!
//! A harness returns quietly whatever the parser answers, error or not: only a panic that
//! reaches the harness (afl.rs turns it into an abort, a crash) or a hang is a finding. Each harness bounds its work:
//! inputs above [`MAX_TEXT`] (or [`MAX_BINARY`] for binary formats) are skipped, file names in
//! an input may only name files in the harness's own directory, and the scene harness lowers
//! `[mesh] max_elements` to [`MAX_FUZZ_ELEMENTS`] and builds one phantom only, the material
//! harness lowers the driver's `max_steps` to [`MAX_FUZZ_DRIVER_STEPS`].

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The largest text input (TOML, JSON, decks, unit strings) a harness reads.
pub const MAX_TEXT: usize = 64 * 1024;
/// The largest binary input (NIfTI, VTU with binary data, models) a harness reads.
pub const MAX_BINARY: usize = 256 * 1024;
/// The most hexahedra a fuzzed box mesh may have (the scene's own `max_elements` is lowered to
/// this).
pub const MAX_FUZZ_ELEMENTS: f64 = 20_000.0;

/// The most steps a fuzzed material driver path may take (its `max_steps` is lowered to this).
pub const MAX_FUZZ_DRIVER_STEPS: f64 = 20_000.0;

/// The targets, by name: the corpus directory `corpus/<name>/` and the binary of that name.
pub const TARGETS: [(&str, fn(&[u8])); 15] = [
    ("scene", scene),
    ("units", units),
    ("material", material),
    ("campaign", campaign),
    ("nifti", nifti),
    ("vtu", vtu),
    ("vtk", vtk),
    ("model", model),
    ("predict_line", predict_line),
    ("serve_message", serve_message),
    ("deck", deck),
    ("gmsh", gmsh),
    ("abaqus", abaqus),
    ("stl", stl),
    ("raw_volume", raw_volume),
];

/// `palpa serve`'s message parser: the binary's own source file, compiled here.
#[path = "../../src/serve/protocol.rs"]
#[allow(dead_code, missing_docs)]
pub mod protocol;

/// `palpa predict --stdin`'s line parser: the binary's own source file, compiled here.
#[path = "../../src/cli/predict_line.rs"]
#[allow(dead_code)]
pub mod predict_line_src;

/// The harness's scratch directory: one per afl instance (or process), created once, with the
/// files a fuzzed input may name (`mesh.vtu`, `curve.csv`, `block-mesh.k`, `hex-nodes.inp`).
pub fn work_dir() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let key = std::env::var("__AFL_SHM_ID").unwrap_or_else(|_| std::process::id().to_string());
        let d = std::env::temp_dir().join(format!("palpa-fuzz-{key}"));
        std::fs::create_dir_all(&d).expect("create the fuzz scratch directory");
        std::fs::write(d.join("mesh.vtu"), FIXTURE_VTU).expect("write mesh.vtu");
        std::fs::write(d.join("block-mesh.k"), FIXTURE_DECK_MESH).expect("write block-mesh.k");
        std::fs::write(d.join("hex-nodes.inp"), FIXTURE_INP_NODES).expect("write hex-nodes.inp");
        std::fs::write(d.join("curve.csv"), "1.0, 0\n1.1, 1 kPa\n1.2, 3 kPa\n")
            .expect("write curve.csv");
        d
    })
}

/// Remove the scratch directory (the corpus replay calls this at its end).
pub fn remove_work_dir() {
    let _ = std::fs::remove_dir_all(work_dir());
}

/// The mesh the example decks include.
const FIXTURE_DECK_MESH: &str = include_str!("../../scenes/decks/block-mesh.k");

/// The nodes of a unit cube, as an Abaqus input file that the `abaqus` seed `include.inp`
/// reads with `*Include, input=hex-nodes.inp`.
const FIXTURE_INP_NODES: &str = "*Node\n1, 0, 0, 0\n2, 1, 0, 0\n3, 1, 1, 0\n4, 0, 1, 0\n\
                                 5, 0, 0, 1\n6, 1, 0, 1\n7, 1, 1, 1\n8, 0, 1, 1\n";

/// A small VTU mesh (of the mesh reader tests) that fuzzed scenes may name as `file = "mesh.vtu"`.
const FIXTURE_VTU: &str = include_str!("../../tests/meshes/vtk-ascii.vtu");

/// With `PALPA_FUZZ_VERBOSE` set (replaying files, not fuzzing), print what the parser
/// answered: to check that seeds get past the parser into the builder.
fn verbose<T, E: std::fmt::Display>(what: &str, r: &Result<T, E>) {
    static ON: OnceLock<bool> = OnceLock::new();
    if *ON.get_or_init(|| std::env::var_os("PALPA_FUZZ_VERBOSE").is_some()) {
        match r {
            Ok(_) => eprintln!("  {what}: ok"),
            Err(e) => eprintln!("  {what}: error: {e}"),
        }
    }
}

fn text(data: &[u8], max: usize) -> Option<&str> {
    if data.len() > max {
        return None;
    }
    std::str::from_utf8(data).ok()
}

/// Whether every file name a TOML input gives (`file`, `path`, `curve_file` keys, at any
/// depth) names a file of the scratch directory: a plain name, no directory.
fn only_local_files(v: &toml::Value) -> bool {
    match v {
        toml::Value::Table(t) => t.iter().all(|(k, v)| {
            let named = matches!(k.as_str(), "file" | "path" | "curve_file");
            let ok = match v {
                toml::Value::String(s) if named => plain_name(s),
                toml::Value::String(_) => true,
                _ if named => true,
                _ => true,
            };
            ok && only_local_files(v)
        }),
        toml::Value::Array(a) => a.iter().all(only_local_files),
        _ => true,
    }
}

fn plain_name(s: &str) -> bool {
    !s.is_empty()
        && s != "."
        && s != ".."
        && !s.starts_with('.')
        && !s.contains(['/', '\\', '\0', ':'])
}

/// The text if it parses as TOML and names local files only.
fn local_toml(data: &[u8]) -> Option<&str> {
    let src = text(data, MAX_TEXT)?;
    let v: toml::Value = toml::from_str(src).ok()?;
    only_local_files(&v).then_some(src)
}

/// Write `data` to `name` in the scratch directory and return its path.
fn scratch_file(name: &str, data: &[u8]) -> PathBuf {
    let p = work_dir().join(name);
    std::fs::write(&p, data).expect("write the fuzz input file");
    p
}

/// A scene file: parsed and built (mesh, node sets, materials, boundary conditions, contact,
/// output plan), not run; as `palpa check` does.
pub fn scene(data: &[u8]) {
    let Some(src) = local_toml(data) else { return };
    let Ok(mut spec) = toml::from_str::<scene::SceneSpec>(src) else {
        return;
    };
    let limit = spec.mesh.max_elements.map_or(MAX_FUZZ_ELEMENTS, |m| m.0);
    spec.mesh.max_elements = Some(material::quantity::Number(limit.min(MAX_FUZZ_ELEMENTS)));
    let mut prebuilt = None;
    if spec.mesh.generator.as_deref() == Some("phantom") {
        // Building a phantom takes about a second: the harness builds one, at
        // FUZZ_PHANTOM_VOXEL, and runs only the scenes that ask for that one (or whose phantom
        // table is refused before a build).
        let ph = fuzz_phantom();
        match spec.mesh.phantom.clone().unwrap_or_default().to_params() {
            Ok(p) if p == ph.params => prebuilt = Some(ph.clone()),
            Ok(_) => return,
            Err(_) => {}
        }
    }
    let path = work_dir().join("scene.toml");
    verbose(
        "scene",
        &scene::build::build_scene_with(spec, &path, src, prebuilt).map(|_| ()),
    );
}

/// The phantom voxel (m) of the scene harness's one phantom.
pub const FUZZ_PHANTOM_VOXEL: f64 = 0.03;

/// The reduced phantom at [`FUZZ_PHANTOM_VOXEL`], built once.
fn fuzz_phantom() -> &'static phantom::Phantom {
    static PH: OnceLock<phantom::Phantom> = OnceLock::new();
    PH.get_or_init(|| {
        let params = phantom::PhantomParams {
            voxel: FUZZ_PHANTOM_VOXEL,
            ..Default::default()
        };
        phantom::build(&params).expect("the fuzz phantom builds")
    })
}

/// Unit strings: a quantity (`"40 kPa"`, `"1.06e-6 kg/mm^3"`) against every dimension, and a
/// deck's unit system (`--units kg-mm-ms`).
pub fn units(data: &[u8]) {
    let Some(s) = text(data, 4096) else { return };
    use material::quantity::{Dim, Quantity};
    if let Ok(q) = Quantity::parse(s) {
        for d in [
            Dim::NONE,
            Dim::LENGTH,
            Dim::TIME,
            Dim::MASS,
            Dim::PRESSURE,
            Dim::DENSITY,
            Dim::VELOCITY,
            Dim::ACCELERATION,
            Dim::FORCE,
            Dim::ENERGY,
            Dim::RATE,
            Dim::STIFFNESS,
        ] {
            let _ = q.get(d);
        }
        if let Some(d) = q.dim {
            let _ = d.name();
        }
    }
    if let Ok(u) = lsdyna::Units::parse(s) {
        let _ = u.to_si(1.0, Dim::PRESSURE);
    }
}

/// A material card: the `palpa material` driver file (law and path, run), or else a bare
/// `[materials.NAME]` card built into its law.
pub fn material(data: &[u8]) {
    let Some(src) = local_toml(data) else { return };
    let dir = work_dir();
    if let Ok(mut spec) = toml::from_str::<material::driver::DriverSpec>(src) {
        let limit = spec.max_steps.map_or(MAX_FUZZ_DRIVER_STEPS, |n| n.0);
        spec.max_steps = Some(material::quantity::Number(limit.min(MAX_FUZZ_DRIVER_STEPS)));
        let r = material::driver::run_driver(&spec, Some(dir));
        verbose("driver", &r);
        if let Ok(out) = r {
            let _ = out.to_csv();
        }
        return;
    }
    if let Ok(card) = toml::from_str::<material::MaterialSpec>(src) {
        verbose("card", &card.build_in("card", Some(dir)).map(|_| ()));
    }
}

/// A campaign file: parsed, resolved into its runs, the phantom parameters checked, and every
/// run's generated scene file parsed back and compared with the scene built in memory (the
/// phantom is not built; `--dry-run` builds it).
pub fn campaign(data: &[u8]) {
    let Some(src) = text(data, MAX_TEXT) else {
        return;
    };
    let Ok(spec) = toml::from_str::<campaign::CampaignSpec>(src) else {
        return;
    };
    let r = spec.resolve();
    verbose("campaign", &r);
    let Ok(c) = r else { return };
    verbose("phantom", &c.phantom_params());
    for r in c.runs.iter().take(64) {
        let _ = c.samples_per_run(r);
        let setup = c.setup(r);
        let scene = setup.scene_toml();
        match toml::from_str::<scene::SceneSpec>(&scene) {
            Err(e) => panic!(
                "run {}: the generated scene does not parse: {e}\n{scene}",
                r.label
            ),
            // the file is the scene that runs
            Ok(parsed) => assert_eq!(
                format!("{parsed:?}"),
                format!("{:?}", setup.scene_spec()),
                "run {}: the scene file differs from the scene built in memory\n{scene}",
                r.label
            ),
        }
    }
}

/// A NIfTI label volume (`.nii`, or `.nii.gz` when the input starts with gzip's magic).
pub fn nifti(data: &[u8]) {
    if data.len() > MAX_BINARY {
        return;
    }
    let name = if data.starts_with(&[0x1f, 0x8b]) {
        "in.nii.gz"
    } else {
        "in.nii"
    };
    verbose(
        "nifti",
        &phantom::voxel::read_nifti(&scratch_file(name, data)),
    );
}

/// A VTK XML unstructured grid (`.vtu`) read as a mesh.
pub fn vtu(data: &[u8]) {
    if data.len() > MAX_BINARY {
        return;
    }
    verbose(
        "vtu",
        &solver::mesh_io::read_mesh(&scratch_file("in.vtu", data), 1.0),
    );
}

/// A legacy VTK file (`.vtk`) read as a mesh.
pub fn vtk(data: &[u8]) {
    if data.len() > MAX_BINARY {
        return;
    }
    verbose(
        "vtk",
        &solver::mesh_io::read_mesh(&scratch_file("in.vtk", data), 1.0),
    );
}

/// The separator of a model input's files: `model.json`, then `model.safetensors`, then
/// optionally `view.json` (and of a raw volume's header and data).
pub const MODEL_SEPARATOR: &[u8] = b"\n--palpa-fuzz-next-file--\n";

/// Split a model input into its files (see [`MODEL_SEPARATOR`]).
pub fn model_files(data: &[u8]) -> Vec<&[u8]> {
    let mut out = Vec::new();
    let mut rest = data;
    while let Some(i) = rest
        .windows(MODEL_SEPARATOR.len())
        .position(|w| w == MODEL_SEPARATOR)
    {
        out.push(&rest[..i]);
        rest = &rest[i + MODEL_SEPARATOR.len()..];
    }
    out.push(rest);
    out
}

/// A surrogate model (`model.json` + `model.safetensors` [+ `view.json`]), loaded as `palpa
/// predict` and `palpa serve` load it, then asked for one prediction.
pub fn model(data: &[u8]) {
    if data.len() > MAX_BINARY {
        return;
    }
    let files = model_files(data);
    let dir = work_dir().join("model");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create the model directory");
    for (f, name) in files
        .iter()
        .zip(["model.json", "model.safetensors", "view.json"])
    {
        std::fs::write(dir.join(name), f).expect("write a model file");
    }
    let r = surrogate::ServedModel::load(&dir);
    verbose("model", &r);
    let Ok(mut served) = r else { return };
    let (x, y, force) = (-0.05, 0.19, 10.0);
    let deviation = {
        let (_, var) = served.predictor.predict_with_variance(x, y, force);
        var.map(|v| (v.max(0.0).sqrt(), 1.0))
    };
    let _ = served.assess(x, y, force, deviation);
    let _ = served.predict(x, y, force);
}

/// `palpa predict --stdin`: each line of the input through the line parser.
pub fn predict_line(data: &[u8]) {
    if data.len() > MAX_TEXT {
        return;
    }
    for line in data.split_inclusive(|&b| b == b'\n') {
        let _ = predict_line_src::parse_input_line(line);
    }
}

/// `palpa serve`'s WebSocket message: the whole input as one text message (and each line as
/// one message of the `--stdin` stream).
pub fn serve_message(data: &[u8]) {
    let Some(s) = text(data, MAX_TEXT) else {
        return;
    };
    let _ = protocol::parse(s);
    if s.contains('\n') {
        for line in s.lines() {
            let _ = protocol::parse(line);
        }
    }
}

/// An LS-DYNA keyword deck, read and assembled into a runnable scene (not run), as `palpa
/// check deck.k` does. `*INCLUDE` may name only files of the scratch directory (which holds
/// `block-mesh.k`, the mesh the example decks include): a deck with a `/` or `\` in the lines
/// of an `*INCLUDE` keyword is skipped.
pub fn deck(data: &[u8]) {
    if data.len() > MAX_TEXT {
        return;
    }
    let upper = data.to_ascii_uppercase();
    let has = |w: &[u8]| upper.windows(w.len()).any(|x| x == w);
    // the lines after an `*INCLUDE...` keyword (file names, or a path) until the next keyword
    let mut in_include = false;
    for line in upper.split(|&b| b == b'\n') {
        if line.starts_with(b"*") {
            in_include = line.starts_with(b"*INCLUDE");
        } else if in_include && line.iter().any(|&b| b == b'/' || b == b'\\') {
            return;
        }
    }
    let path = scratch_file("in.k", data);
    // a deck without *CONTROL_UNITS needs the user's unit system (`--units`)
    let opts = lsdyna::ReadOptions {
        units: (!has(b"*CONTROL_UNITS"))
            .then(|| lsdyna::Units::parse("kg-mm-ms").expect("a unit system")),
        ignore_palpa_comments: false,
    };
    let r = lsdyna::load_deck(&path, &opts);
    verbose(
        "deck",
        &r.as_ref().map(|_| ()).map_err(|e| e.errors.join("; ")),
    );
}

/// A Gmsh mesh (`.msh`, format 4.1, ASCII or binary) read as a mesh.
pub fn gmsh(data: &[u8]) {
    if data.len() > MAX_BINARY {
        return;
    }
    verbose(
        "gmsh",
        &solver::mesh_io::read_mesh(&scratch_file("in.msh", data), 1.0),
    );
}

/// An Abaqus input file (`.inp`) read as a mesh. `*Include` may name only files of the scratch
/// directory (which holds `hex-nodes.inp`): an input with a `/` or `\` in a keyword line that
/// mentions `include` is skipped.
pub fn abaqus(data: &[u8]) {
    if data.len() > MAX_TEXT {
        return;
    }
    for line in String::from_utf8_lossy(data).lines() {
        let t = line.trim_start();
        if t.starts_with('*')
            && t.to_ascii_lowercase().contains("include")
            && t.contains(['/', '\\'])
        {
            return;
        }
    }
    verbose(
        "abaqus",
        &solver::mesh_io::read_mesh(&scratch_file("in.inp", data), 1.0),
    );
}

/// An STL surface (ASCII or binary) read as a rigid indenter's shape, as a scene's
/// `shape = { stl = ... }` is (in mm), then its signed distance at a few points, as contact
/// queries it.
pub fn stl(data: &[u8]) {
    if data.len() > MAX_BINARY {
        return;
    }
    let spec = contact::ShapeSpec::Stl {
        path: scratch_file("in.stl", data),
        scale: 1e-3,
        translate: [0.0; 3],
    };
    let r = contact::Shape::from_spec(&spec);
    verbose("stl", &r);
    let Ok(shape) = r else { return };
    if let Some(bb) = shape.aabb() {
        let mid = std::array::from_fn(|k| 0.5 * (bb.min[k] + bb.max[k]));
        let out = std::array::from_fn(|k| 2.0 * bb.max[k] - bb.min[k]);
        for x in [bb.min, bb.max, mid, out] {
            let _ = shape.signed_distance(x);
        }
    }
}

/// A raw label volume: its JSON header and its raw bytes, joined by the line of
/// [`MODEL_SEPARATOR`], written as `volume.json` and `volume.raw` and read as `palpa mesh image`
/// reads it (`phantom::voxel::read_volume`), then its label counts. The header's `data` may only
/// name a file of the scratch directory; an input whose `data` names another is skipped.
pub fn raw_volume(data: &[u8]) {
    if data.len() > MAX_BINARY {
        return;
    }
    let files = model_files(data);
    if let Ok(serde_json::Value::Object(h)) = serde_json::from_slice(files[0]) {
        if let Some(serde_json::Value::String(name)) = h.get("data") {
            if !plain_name(name) {
                return;
            }
        }
    }
    let json = scratch_file("volume.json", files[0]);
    let raw = work_dir().join("volume.raw");
    match files.get(1) {
        Some(b) => std::fs::write(&raw, b).expect("write volume.raw"),
        None => {
            let _ = std::fs::remove_file(&raw);
        }
    }
    let r = phantom::voxel::read_volume(&json);
    verbose("raw_volume", &r);
    if let Ok(v) = r {
        let _ = v.label_counts();
    }
}

/// Without afl (a plain `cargo build`): run the harness on each file named on the command
/// line, to reproduce a finding under a debugger or with a backtrace.
pub fn replay_args(name: &str, harness: fn(&[u8])) {
    let files: Vec<String> = std::env::args().skip(1).collect();
    if files.is_empty() {
        eprintln!(
            "usage: {name} FILE... (built without afl: replays the files through the harness)"
        );
        std::process::exit(2);
    }
    for f in files {
        let data = std::fs::read(&f).unwrap_or_else(|e| panic!("{f}: {e}"));
        eprintln!("{name}: {f} ({} bytes)", data.len());
        harness(&data);
    }
    eprintln!("{name}: no panic");
}
