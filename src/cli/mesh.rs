//! `palpa mesh phantom ...` and `palpa mesh image ...`: build the procedural abdomen phantom, or
//! mesh a user's own labelled segmentation, write the mesh (`.vtu`) and/or the label volume
//! (`.nii`, `.nii.gz`), and print counts per part, quality figures, timings and memory.
//!
//! Lengths on the command line take a unit (`3mm`, `"1.5 cm"`, `0.003 m`); a plain number is
//! SI (metres), as in scene files (parsed by `material::quantity`).

use clap::{Args, Subcommand};
use material::quantity::{Dim, Quantity};
use phantom::voxel::{self, LabelMap, LabelVolume, MeshOptions, MeshQuality};
use phantom::{self, PhantomParams, Tumour, Variant};
use solver::mesh::Mesh;
use solver::output::atomic::write_atomic;
use solver::output::vtk::{write_vtu, Frame};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// `palpa mesh ...`
#[derive(Subcommand)]
pub enum MeshCommand {
    /// Build the procedural abdomen phantom (flesh, liver, ribs, viscera, spine, optional
    /// tumours) and write its hexahedral mesh and/or label volume.
    ///
    /// OUTPUTS (--out, may be given several times): a name ending in `.vtu` gets the smoothed
    /// hexahedral mesh (VTK XML, cell array `part_id`; the report lists which id is which
    /// part); `.nii` or `.nii.gz` gets the label volume that was meshed (cropped for the
    /// reduced variant, before coarsening and clean-up: `palpa mesh image` with the same
    /// --coarsen and a label map 1 flesh, 2 liver, 3 ribs, 4 viscera, 5 spine, 6.. tumours
    /// reproduces the mesh; with --skin fitted it is the body's labels on the plain grid, which
    /// the mesh came from stretched). A directory (an existing one, a name ending in `/`, or a name
    /// with no extension) gets both, as `phantom.vtu` and `phantom.nii.gz`. Next to every
    /// output (in its directory) go `roi.json` and `roi.csv` (region-of-interest element ids
    /// and centroids, m) and `locations.json` (the 5x5 palpation raster and the test
    /// locations A, B, C). Without --out nothing is written but the report (and --preview).
    ///
    /// FRAME (m): x towards the patient's left (0 on the midline; the liver is at x < 0),
    /// y cranial (0 at the caudal end of the torso), z anterior (0 on the back, skin at about
    /// 220 mm).
    Phantom(PhantomArgs),
    /// Mesh a labelled segmentation (NIfTI `.nii`/`.nii.gz`, or raw + JSON header `.json`):
    /// one hexahedron per labelled voxel, clean-up, smoothing.
    ///
    /// OUTPUTS (--out, may be given several times): `.vtu` gets the mesh (cell array
    /// `part_id`, numbered in the order of the label map's parts, listed in the report);
    /// `.nii`/`.nii.gz` a copy of the input volume (a format conversion); a directory gets
    /// `mesh.vtu`. See scenes/labels-example.toml for a label map.
    Image(ImageArgs),
    /// Read a hexahedral mesh another tool wrote (VTK `.vtu`/`.vtk` as VTK, ParaView or meshio
    /// write them, Gmsh `.msh` 4.1, Abaqus `.inp`), check it as a scene's `[mesh] file` would
    /// be checked, report its parts, sets and quality, and optionally write it as palpa's
    /// `.vtu` (cell array `part_id`, part names in the field data `part_names`).
    Import(ImportArgs),
}

/// `palpa mesh import` options.
#[derive(Args)]
pub struct ImportArgs {
    /// The mesh file.
    file: PathBuf,
    /// The length unit of the file's coordinates (`mm`, `m`, ...); required for Gmsh and
    /// Abaqus files, which carry none; VTK files default to m.
    #[arg(long, value_name = "UNIT")]
    units: Option<String>,
    /// Write the mesh, in m, to this `.vtu`.
    #[arg(long, value_name = "FILE.vtu")]
    out: Option<PathBuf>,
}

/// Options shared by both mesh commands.
#[derive(Args)]
pub struct CommonArgs {
    /// Output file(s) or directory; see the command's help for what each extension gets.
    #[arg(long, value_name = "FILE|DIR")]
    out: Vec<PathBuf>,
    /// Merge N x N x N voxels into one by majority label before meshing.
    #[arg(long, value_name = "N", default_value_t = 1)]
    coarsen: usize,
    /// Taubin smoothing iterations of the outer surface and part interfaces (0: a pure
    /// staircase voxel mesh).
    #[arg(long, value_name = "N", default_value_t = MeshOptions::default().smoothing.iterations)]
    smooth_iterations: usize,
    /// Write PNG slices (axial, sagittal, coronal) with the labels coloured into DIR.
    #[arg(long, value_name = "DIR")]
    preview: Option<PathBuf>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    threads: Option<usize>,
}

impl CommonArgs {
    fn mesh_options(&self) -> Result<MeshOptions, String> {
        if self.coarsen == 0 {
            return Err("--coarsen must be at least 1".into());
        }
        let mut o = MeshOptions {
            coarsen: self.coarsen,
            ..Default::default()
        };
        o.smoothing.iterations = self.smooth_iterations;
        Ok(o)
    }
}

/// `palpa mesh phantom` options. Lengths take a unit (`3mm`); a plain number is metres.
#[derive(Args)]
pub struct PhantomArgs {
    /// `full`: the whole torso; `reduced`: the upper liver and the tissue around it, cropped
    /// to a box (fixed bottom, rollers on the cut planes).
    #[arg(long, default_value = "reduced", value_parser = ["full", "reduced"])]
    variant: String,
    /// Voxel edge length = element size [default: 5mm; the paper's CT is about 3mm].
    #[arg(long, value_name = "LENGTH", value_parser = length)]
    voxel: Option<f64>,
    /// Subcutaneous fat (flesh) thickness over the muscle and rib layer [default: 15mm].
    #[arg(long, value_name = "LENGTH", value_parser = length)]
    fat: Option<f64>,
    /// Respiratory phase, 0 (full exhalation, the paper's frame) to 1 (full inspiration)
    /// [default: 0].
    #[arg(long, value_name = "0..1")]
    phase: Option<f64>,
    /// The anterior skin: `voxel` (smoothed voxel steps) or `fitted` (one node layer on the
    /// body's outline, the grid's columns stretched to meet it).
    #[arg(long, default_value = "voxel", value_parser = ["voxel", "fitted"])]
    skin: String,
    /// Caudal liver displacement at phase 1 [default: 20mm].
    #[arg(long, value_name = "LENGTH", value_parser = length)]
    max_shift: Option<f64>,
    /// Torso width, left to right [default: 300mm].
    #[arg(long, value_name = "LENGTH", value_parser = length)]
    torso_width: Option<f64>,
    /// Torso depth, back to front [default: 220mm].
    #[arg(long, value_name = "LENGTH", value_parser = length)]
    torso_depth: Option<f64>,
    /// Torso length, caudal to cranial [default: 300mm].
    #[arg(long, value_name = "LENGTH", value_parser = length)]
    torso_length: Option<f64>,
    /// A spherical liver tumour (repeatable): centre x,y,z (phantom frame at phase 0; it
    /// moves with the liver), radius, and stiffness relative to liver, e.g.
    /// `--tumour=-70mm,230mm,160mm,12mm,5`. Tumours become parts "tumour", "tumour2", ...
    #[arg(long, value_name = "X,Y,Z,R,FACTOR", value_parser = tumour, allow_hyphen_values = true)]
    tumour: Vec<Tumour>,
    /// Region-of-interest centre x,y,z [default: on the liver's inferior edge below the
    /// palpation raster's centre].
    #[arg(long, value_name = "X,Y,Z", value_parser = point3, allow_hyphen_values = true)]
    roi_center: Option<[f64; 3]>,
    /// ROI: liver surface elements with centroid within this distance of the centre
    /// [default: 60mm].
    #[arg(long, value_name = "LENGTH", value_parser = length)]
    roi_radius: Option<f64>,
    /// ROI: keep at most this many elements, nearest first; 0 for no limit [default: 377,
    /// the paper's].
    #[arg(long, value_name = "N")]
    roi_count: Option<usize>,
    /// Palpation raster centre x,y [default: -50mm,195mm].
    #[arg(long, value_name = "X,Y", value_parser = point2, allow_hyphen_values = true)]
    grid_center: Option<[f64; 2]>,
    /// Palpation raster spacing along x,y [default: 25mm,15mm].
    #[arg(long, value_name = "DX,DY", value_parser = point2)]
    grid_spacing: Option<[f64; 2]>,
    /// Palpation raster points along x,y [default: 5,5].
    #[arg(long, value_name = "NX,NY", value_parser = counts2)]
    grid_points: Option<[usize; 2]>,
    #[command(flatten)]
    common: CommonArgs,
}

/// `palpa mesh image` options.
#[derive(Args)]
pub struct ImageArgs {
    /// The label volume: `.nii`, `.nii.gz`, or `.json` (raw + JSON header).
    labels_file: PathBuf,
    /// Label map (TOML, `label = "part"`; several labels may share a part). Without it every
    /// label present becomes a part `label_N`.
    #[arg(long, value_name = "MAP.toml")]
    labels: Option<PathBuf>,
    #[command(flatten)]
    common: CommonArgs,
}

/// Parse a length: `3mm`, `"3 mm"`, `0.3 cm`; a plain number is metres ([`super::units`]).
fn length(s: &str) -> Result<f64, String> {
    super::units::length(s, "length")
}

fn lengths(s: &str, n: usize) -> Result<Vec<f64>, String> {
    super::units::lengths(s, n, "lengths")
}

fn point3(s: &str) -> Result<[f64; 3], String> {
    let v = lengths(s, 3)?;
    Ok([v[0], v[1], v[2]])
}

fn point2(s: &str) -> Result<[f64; 2], String> {
    let v = lengths(s, 2)?;
    Ok([v[0], v[1]])
}

fn counts2(s: &str) -> Result<[usize; 2], String> {
    let v: Vec<usize> = s
        .split(',')
        .map(|p| p.trim().parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("`{s}`: expected two counts NX,NY"))?;
    match v[..] {
        [a, b] if a > 0 && b > 0 => Ok([a, b]),
        _ => Err(format!("`{s}`: expected two positive counts NX,NY")),
    }
}

fn tumour(s: &str) -> Result<Tumour, String> {
    let parts: Vec<&str> = s.split(',').collect();
    if parts.len() != 5 {
        return Err(format!(
            "`{s}`: expected X,Y,Z,RADIUS,STIFFNESS_FACTOR (5 values), got {}",
            parts.len()
        ));
    }
    let c = [length(parts[0])?, length(parts[1])?, length(parts[2])?];
    let radius = length(parts[3])?;
    let stiffness_factor = Quantity::parse(parts[4])?.get(Dim::NONE)?;
    if !(radius > 0.0 && stiffness_factor > 0.0) {
        return Err(format!(
            "`{s}`: tumour radius and stiffness factor must be positive"
        ));
    }
    Ok(Tumour {
        center: c,
        radius,
        stiffness_factor,
    })
}

/// Where the outputs go.
#[derive(Default, Debug)]
struct Targets {
    vtu: Vec<PathBuf>,
    nii: Vec<PathBuf>,
    /// Directories of all outputs (for the phantom's side files), in order, unique.
    dirs: Vec<PathBuf>,
}

fn is_nifti(p: &Path) -> bool {
    let n = p.to_string_lossy().to_ascii_lowercase();
    n.ends_with(".nii") || n.ends_with(".nii.gz")
}

fn resolve_outputs(outs: &[PathBuf], dir_files: &[&str]) -> Result<Targets, String> {
    let mut t = Targets::default();
    for o in outs {
        let s = o.to_string_lossy();
        let is_dir = o.is_dir()
            || s.ends_with('/')
            || s.ends_with(std::path::MAIN_SEPARATOR)
            || o.extension().is_none();
        let (files, dir) = if is_dir {
            (
                dir_files.iter().map(|f| o.join(f)).collect::<Vec<_>>(),
                o.clone(),
            )
        } else {
            let dir = o
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .map(Path::to_path_buf)
                .unwrap_or_else(|| PathBuf::from("."));
            (vec![o.clone()], dir)
        };
        for f in files {
            let lower = f.to_string_lossy().to_ascii_lowercase();
            if lower.ends_with(".vtu") {
                t.vtu.push(f);
            } else if is_nifti(&f) {
                t.nii.push(f);
            } else {
                return Err(format!(
                    "--out {}: unknown extension (use .vtu, .nii, .nii.gz, or a directory)",
                    f.display()
                ));
            }
        }
        if !t.dirs.contains(&dir) {
            t.dirs.push(dir);
        }
    }
    for d in &t.dirs {
        std::fs::create_dir_all(d)
            .map_err(|e| format!("{}: cannot create directory: {e}", d.display()))?;
    }
    Ok(t)
}

/// Write a NIfTI volume atomically: a hidden temporary beside the target (same `.nii` /
/// `.nii.gz` ending, so the compression matches), then rename.
fn write_nifti_atomic(vol: &LabelVolume, path: &Path) -> Result<(), String> {
    let name = path
        .file_name()
        .ok_or_else(|| format!("{}: not a file name", path.display()))?
        .to_string_lossy()
        .into_owned();
    let ext = if name.to_ascii_lowercase().ends_with(".nii.gz") {
        "nii.gz"
    } else {
        "nii"
    };
    let tmp = path.with_file_name(format!(".{name}.{}.tmp.{ext}", std::process::id()));
    solver::output::atomic::write_atomic_with(path, &tmp, |tmp| voxel::write_nifti(vol, tmp))
}

fn write_mesh(mesh: &Mesh, path: &Path, title: &str) -> Result<(), String> {
    let frame = Frame {
        part: true,
        ..Default::default()
    };
    write_vtu(path, mesh, &frame, title)
}

/// Peak resident memory of this process (Linux), in bytes.
fn peak_rss() -> Option<usize> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: usize = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Part ids, meshing time and memory (after the counts and quality of `MeshQuality::summary`,
/// which `Phantom::summary` includes).
fn print_report(q: &MeshQuality, parts: &[String]) {
    let ids: Vec<String> = parts
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{i} {n}"))
        .collect();
    println!("part_id: {}", ids.join(", "));
    println!(
        "meshing + smoothing wall time: {:.2} s (clean-up and hexahedra {:.2} s, smoothing {:.2} s) on {} thread(s)",
        q.seconds_mesh + q.seconds_smooth,
        q.seconds_mesh,
        q.seconds_smooth,
        rayon::current_num_threads()
    );
    match peak_rss() {
        Some(b) => println!(
            "memory: mesh {:.1} MB; peak resident (so far) {:.1} MB",
            q.mesh_bytes as f64 / 1e6,
            b as f64 / 1e6
        ),
        None => println!("memory: mesh {:.1} MB", q.mesh_bytes as f64 / 1e6),
    }
}

/// Run `palpa mesh ...`.
pub fn mesh(cmd: MeshCommand) -> Result<(), String> {
    match cmd {
        MeshCommand::Phantom(a) => mesh_phantom(a),
        MeshCommand::Image(a) => mesh_image(a),
        MeshCommand::Import(a) => mesh_import(a),
    }
}

fn mesh_import(a: ImportArgs) -> Result<(), String> {
    let ext = a
        .file
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let scale = match &a.units {
        Some(u) => Quantity::parse(&format!("1 {u}"))
            .and_then(|q| q.get(Dim::LENGTH))
            .map_err(|e| format!("--units {u}: {e}"))?,
        None if ext == "msh" || ext == "inp" => {
            return Err(format!(
                "{}: a {} file states no unit; give the length unit of its coordinates, e.g. --units mm",
                a.file.display(),
                if ext == "msh" { "Gmsh" } else { "Abaqus" }
            ))
        }
        None => 1.0,
    };
    let imported = solver::mesh_io::read_mesh(&a.file, scale)?;
    let mesh = &imported.mesh;
    let q = MeshQuality::measure(mesh);
    let (lo, hi) = mesh.bounds();
    println!(
        "{}: {} nodes, {} hexahedra, {} part(s); extent {:.3} x {:.3} x {:.3} mm from ({:.3}, {:.3}, {:.3}) mm",
        a.file.display(),
        q.n_nodes,
        q.n_elements,
        mesh.part_names.len(),
        (hi[0] - lo[0]) * 1e3,
        (hi[1] - lo[1]) * 1e3,
        (hi[2] - lo[2]) * 1e3,
        lo[0] * 1e3,
        lo[1] * 1e3,
        lo[2] * 1e3
    );
    for (i, (name, c)) in q.part_counts.iter().enumerate() {
        println!("  part_id {i} {name:<16} {c:>9} hexahedra");
    }
    for (name, s) in &mesh.node_sets {
        println!("  node set    {name:<16} {:>9} nodes", s.len());
    }
    for (name, s) in &mesh.element_sets {
        println!("  element set {name:<16} {:>9} hexahedra", s.len());
    }
    println!(
        "scaled Jacobian: min {:.3}, mean {:.3}; shortest edge {:.3} mm, smallest V/A_max {:.3} mm",
        q.min_scaled_jacobian,
        q.mean_scaled_jacobian,
        q.min_edge * 1e3,
        q.min_char_length * 1e3
    );
    for n in &imported.notes {
        println!("note: {n}");
    }
    if let Some(out) = &a.out {
        write_mesh(mesh, out, &format!("palpa import of {}", a.file.display()))?;
        print_written(&[out.clone()]);
    }
    Ok(())
}

fn mesh_phantom(a: PhantomArgs) -> Result<(), String> {
    super::set_threads(a.common.threads)?;
    let mut p = PhantomParams {
        variant: a.variant.parse::<Variant>()?,
        mesh: a.common.mesh_options()?,
        tumours: a.tumour.clone(),
        ..Default::default()
    };
    if let Some(v) = a.voxel {
        p.voxel = v;
    }
    if let Some(v) = a.fat {
        p.fat_thickness = v;
    }
    if let Some(v) = a.phase {
        p.respiratory_phase = v;
    }
    p.skin = a.skin.parse()?;
    if let Some(v) = a.max_shift {
        p.max_liver_shift = v;
    }
    if let Some(v) = a.torso_width {
        p.torso_width = v;
    }
    if let Some(v) = a.torso_depth {
        p.torso_depth = v;
    }
    if let Some(v) = a.torso_length {
        p.torso_length = v;
    }
    if a.roi_center.is_some() {
        p.roi.center = a.roi_center;
    }
    if let Some(r) = a.roi_radius {
        if !(r > 0.0) {
            return Err("--roi-radius must be positive".into());
        }
        p.roi.radius = r;
    }
    if let Some(n) = a.roi_count {
        p.roi.max_count = if n == 0 { None } else { Some(n) };
    }
    if let Some(c) = a.grid_center {
        p.grid.center = c;
    }
    if let Some(s) = a.grid_spacing {
        if !(s[0] > 0.0 && s[1] > 0.0) {
            return Err("--grid-spacing must be positive".into());
        }
        p.grid.spacing = s;
    }
    if let Some(n) = a.grid_points {
        p.grid.n = n;
    }
    p.validate()?;
    let targets = resolve_outputs(&a.common.out, &["phantom.vtu", "phantom.nii.gz"])?;

    let t0 = Instant::now();
    let ph = phantom::build(&p)?;
    let build_s = t0.elapsed().as_secs_f64();
    println!("{}", ph.summary());
    print_report(&ph.quality, &ph.mesh.part_names);
    println!(
        "phantom built in {:.2} s (voxelisation, meshing, smoothing, ROI, locations); label volume {} x {} x {} = {} voxels",
        build_s,
        ph.volume.dims[0],
        ph.volume.dims[1],
        ph.volume.dims[2],
        ph.volume.len()
    );
    if !ph.tumours.is_empty() {
        for (name, f) in &ph.tumours {
            println!("  {name}: stiffness factor {f}");
        }
    }

    let title = format!(
        "palpa phantom {:?}, voxel {:.2} mm",
        p.variant,
        p.voxel * 1e3
    );
    let mut written = Vec::new();
    for f in &targets.vtu {
        write_mesh(&ph.mesh, f, &title)?;
        written.push(f.clone());
    }
    for f in &targets.nii {
        write_nifti_atomic(&ph.volume, f)?;
        written.push(f.clone());
    }
    for d in &targets.dirs {
        for (name, text) in [
            ("roi.json", ph.roi.to_json()),
            ("roi.csv", ph.roi.to_csv()),
            ("locations.json", ph.locations.to_json()),
        ] {
            let f = d.join(name);
            write_atomic(&f, text.as_bytes())?;
            written.push(f);
        }
    }
    if let Some(dir) = &a.common.preview {
        written.extend(ph.write_preview(dir)?);
    }
    print_written(&written);
    Ok(())
}

fn print_written(written: &[PathBuf]) {
    if written.is_empty() {
        println!("nothing written (give --out FILE.vtu, FILE.nii.gz or DIR, or --preview DIR)");
    } else {
        let w: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
        println!("wrote {}", w.join(", "));
    }
}

fn mesh_image(a: ImageArgs) -> Result<(), String> {
    super::set_threads(a.common.threads)?;
    let opts = a.common.mesh_options()?;
    let targets = resolve_outputs(&a.common.out, &["mesh.vtu"])?;
    let path = &a.labels_file;
    if !path.exists() {
        return Err(format!("label volume {} does not exist", path.display()));
    }
    let vol = voxel::read_volume(path).map_err(|e| name_file(path, e))?;
    let counts = vol.label_counts();
    let map = match &a.labels {
        Some(m) => LabelMap::from_toml_file(m).map_err(|e| name_file(m, e))?,
        None => LabelMap::identity(&counts),
    };
    println!(
        "{}: {} x {} x {} voxels, spacing {:.3} x {:.3} x {:.3} mm",
        path.display(),
        vol.dims[0],
        vol.dims[1],
        vol.dims[2],
        vol.spacing[0] * 1e3,
        vol.spacing[1] * 1e3,
        vol.spacing[2] * 1e3
    );
    let present: Vec<String> = (1..256)
        .filter(|&l| counts[l] > 0)
        .map(|l| {
            format!(
                "{l} ({}): {}",
                map.labels
                    .get(&(l as u8))
                    .map(String::as_str)
                    .unwrap_or("unmapped"),
                counts[l]
            )
        })
        .collect();
    println!("labels present: {}", present.join(", "));
    let (mesh, q) = voxel::mesh_volume(&vol, &map, &opts).map_err(|e| {
        format!(
            "{}{}: {e}",
            path.display(),
            a.labels
                .as_ref()
                .map(|m| format!(" with {}", m.display()))
                .unwrap_or_default()
        )
    })?;
    println!("{}", q.summary());
    print_report(&q, &mesh.part_names);
    let title = format!("palpa mesh of {}", path.display());
    let mut written = Vec::new();
    for f in &targets.vtu {
        write_mesh(&mesh, f, &title)?;
        written.push(f.clone());
    }
    for f in &targets.nii {
        write_nifti_atomic(&vol, f)?;
        written.push(f.clone());
    }
    if let Some(dir) = &a.common.preview {
        written.extend(voxel::write_preview(&vol, dir)?);
    }
    print_written(&written);
    Ok(())
}

/// Make sure an error names the file.
fn name_file(path: &Path, e: String) -> String {
    if e.contains(&path.display().to_string()) {
        e
    } else {
        format!("{}: {e}", path.display())
    }
}
