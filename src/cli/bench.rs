//! `palpa bench`: whole-run throughput of the explicit step, measured the way a user runs it.
//!
//! Every case is a real scene (built by the scene builder, with the stages that scene plans),
//! stepped `--steps` times after its first force evaluation, inside a rayon pool of each
//! requested thread count. Reported per case and thread count:
//! - element-cycles per second = elements x steps / wall time of the stepping loop;
//! - the share of step time of every active stage (element forces, update, contact, ...);
//! - the speed-up of N threads over 1 thread, both measured in the same invocation.
//!
//! Cases (issue 2 and issue 4 of the tracker):
//! - `nh-1pt`: a 100k-element (50 x 50 x 40) neo-Hookean block, one-point elements with viscous
//!   hourglass control, fixed base and a top velocity load; floor 5 M element-cycles/s on
//!   2 threads, aim 15 M;
//! - `nh-fbar`: the same block with fully integrated F-bar elements;
//! - `press`: the same block of the paper's flesh (simplified rubber/foam, K/G = 5e4, 2.8 mm
//!   elements), pressed by the two-finger hand already in contact: the contact stage's share of
//!   the step must stay at most 10 %;
//! - `ogden`: the same block of the paper's liver (Ogden, exponents 19 and -11, three Prony
//!   terms), one-point elements with shear-scaled stiffness hourglass control, top velocity load.
//!
//! `--numbering as_given,shuffled,rcm` runs every case with the block's nodes as generated
//! (a raster), in a seeded random order and renumbered by reverse Cuthill-McKee
//! ([`solver::renumber`]): what locality is worth, and what RCM recovers.
//!
//! The memory roof: a STREAM-style triad `a = b + s c` over 3 x 64 MB, run on the same threads
//! just before each case, gives the bandwidth; the bytes a step moves per element (its reference
//! data, history read and written, and nodal arrays: three gathered, the force array added into
//! and about seven swept by the update, per node) divided into
//! it give the case's roof in element-cycles per second, and the table prints the fraction of
//! that roof the case reaches. The bytes are a count of the arrays the step touches, not a
//! hardware measurement: cache reuse of the gathered nodal data can beat the roof.

use scene::build::build_scene;
use scene::SceneSpec;
use solver::element::precision::Precision;
use solver::renumber::Numbering;
use std::path::Path;
use std::time::Instant;

/// The block shared by every case: 50 x 50 x 40 elements of 2.8 mm (the paper's voxel), its
/// nodes numbered `numbering`.
fn block(numbering: Numbering) -> String {
    format!(
        r#"
[mesh]
generator = "box"
origin = ["-70 mm", "-70 mm", "-112 mm"]
size = ["140 mm", "140 mm", "112 mm"]
divisions = [50, 50, 40]
part = "body"
numbering = "{}"

[[boundary]]
nodes = "zmin"
fix = ["all"]

[output]
vtk = false
"#,
        numbering.label()
    )
}

fn case_scene(case: &str, precision: Precision, numbering: Numbering) -> Result<String, String> {
    let nh = r#"
[materials.nh]
law = "neo_hookean"
density = "1000 kg/m^3"
youngs_modulus = "1 MPa"
poisson_ratio = 0.45
"#;
    let top_load = r#"
[[boundary]]
nodes = "zmax"
velocity = { z = { kind = "constant", value = "-0.1 m/s" } }
"#;
    let body = match case {
        "nh-1pt" => format!(
            "{nh}{top_load}[[part]]\nname = \"body\"\nmaterial = \"nh\"\nformulation = \"one_point\"\nhourglass = \"viscous\"\n"
        ),
        "nh-fbar" => format!(
            "{nh}{top_load}[[part]]\nname = \"body\"\nmaterial = \"nh\"\nformulation = \"full_fbar\"\n"
        ),
        "press" => r#"
[[part]]
name = "body"
material = "paper:flesh"
hourglass = "stiffness"
hourglass_modulus = "shear"

[[hand]]
name = "hand"
point = ["0 mm", "0 mm", "0 mm"]
direction = [0, 0, -1]
spacing_axis = [1, 0, 0]
diameter = "15 mm"
spacing = "20 mm"
length = "60 mm"
gap = "0 mm"
motion = { kind = "velocity", curve = { kind = "constant", value = "0.6 m/s" } }

[contact]
surface = "zmax"
"#
        .to_string(),
        "ogden" => format!(
            "{top_load}[[part]]\nname = \"body\"\nmaterial = \"paper:liver\"\nhourglass = \"stiffness\"\nhourglass_modulus = \"shear\"\n"
        ),
        o => {
            return Err(format!(
                "unknown bench case `{o}` (nh-1pt, nh-fbar, press, ogden)"
            ))
        }
    };
    let block = block(numbering);
    Ok(format!(
        "[run]\ntitle = \"bench {case}\"\nend_time = \"1 s\"\nprecision = \"{}\"\n{block}{body}",
        precision.label()
    ))
}

/// One measurement.
struct Measured {
    elements: usize,
    seconds: f64,
    stages: Vec<(&'static str, f64)>,
    /// Bytes the step moves per element-cycle (see the module doc).
    bytes_per_element: f64,
    /// Triad bandwidth measured on the same threads just before (bytes/s).
    bandwidth: f64,
}

/// STREAM-style triad bandwidth (bytes/s) on the current rayon pool: best of three passes over
/// three arrays of 8 M doubles (3 x 64 MB, far beyond any cache), counting 24 bytes per index.
fn triad_bandwidth() -> f64 {
    use rayon::prelude::*;
    let n = 8 << 20;
    let b = vec![1.0f64; n];
    let c = vec![2.0f64; n];
    let mut a = vec![0.0f64; n];
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let t0 = Instant::now();
        a.par_chunks_mut(1 << 16)
            .zip(b.par_chunks(1 << 16).zip(c.par_chunks(1 << 16)))
            .for_each(|(a, (b, c))| {
                for ((a, b), c) in a.iter_mut().zip(b).zip(c) {
                    *a = b + 3.0 * c;
                }
            });
        best = best.min(t0.elapsed().as_secs_f64());
        std::hint::black_box(&a);
    }
    (24 * n) as f64 / best
}

/// Bytes one step moves per element (module doc): reference data and history of every group,
/// and 11 nodal arrays of 24 bytes (the force array is read and written by the element loop).
fn step_bytes_per_element(m: &solver::model::Model) -> f64 {
    let mut bytes = 0usize;
    for g in &m.groups {
        let reference = g.kernel_bytes();
        bytes += g.conn.len() * (32 + 8 + 8)
            + reference
            + 2 * std::mem::size_of_val(g.history.as_slice())
            + 8 * g.density_scale.len();
    }
    bytes += 11 * 24 * m.mesh.nodes.len();
    bytes as f64 / m.mesh.elements.len() as f64
}

fn measure(
    case: &str,
    threads: usize,
    steps: usize,
    precision: Precision,
    numbering: Numbering,
) -> Result<Measured, String> {
    let src = case_scene(case, precision, numbering)?;
    let spec: SceneSpec = toml::from_str(&src).map_err(|e| format!("bench scene {case}: {e}"))?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| e.to_string())?;
    pool.install(|| {
        let bandwidth = triad_bandwidth();
        let mut scene = build_scene(spec, Path::new(&format!("bench-{case}.toml")), &src)?;
        let sim = &mut scene.sim;
        sim.initialise().map_err(|e| e.to_string())?;
        for t in sim.timers.iter_mut() {
            t.time = std::time::Duration::ZERO;
        }
        let t0 = Instant::now();
        for _ in 0..steps {
            sim.step(f64::INFINITY).map_err(|e| e.to_string())?;
        }
        let seconds = t0.elapsed().as_secs_f64();
        let total: f64 = sim.timers.iter().map(|t| t.time.as_secs_f64()).sum();
        Ok(Measured {
            elements: sim.model.mesh.elements.len(),
            bytes_per_element: step_bytes_per_element(&sim.model),
            bandwidth,
            seconds,
            stages: sim
                .timers
                .iter()
                .filter(|t| !t.time.is_zero())
                .map(|t| (t.name, t.time.as_secs_f64() / total.max(1e-300)))
                .collect(),
        })
    })
}

/// Run the benchmark cases and print the table.
pub fn bench(
    cases: &[String],
    threads: &[usize],
    steps: usize,
    precisions: &[String],
    numberings: &[String],
) -> Result<(), String> {
    let precisions = precisions
        .iter()
        .map(|p| Precision::parse(p).map_err(|e| format!("--precision: {e}")))
        .collect::<Result<Vec<_>, _>>()?;
    let numberings = numberings
        .iter()
        .map(|n| Numbering::parse(n).map_err(|e| format!("--numbering: {e}")))
        .collect::<Result<Vec<_>, _>>()?;
    if steps == 0 {
        return Err("--steps must be at least 1".into());
    }
    if let Some(0) = threads.iter().find(|&&t| t == 0) {
        return Err("--threads: every thread count must be at least 1".into());
    }
    println!(
        "palpa bench: {steps} steps per case, element-cycles per second = elements x steps / wall time; \
         element kernels: {} (8 lanes)",
        solver::forces::simd_level()
    );
    println!(
        "{:<16} {:>4} {:>7} {:>9} {:>9} {:>12} {:>8} {:>7} {:>9} {:>10} {:>7}  stage shares",
        "case",
        "prec",
        "threads",
        "elements",
        "wall s",
        "M el-cyc/s",
        "speedup",
        "B/el",
        "triad GB/s",
        "roof M/s",
        "of roof"
    );
    let runs = cases.iter().flat_map(|c| {
        let numberings = &numberings;
        precisions
            .iter()
            .flat_map(move |p| numberings.iter().map(move |n| (c, *p, *n)))
    });
    for (case, p, n) in runs {
        let mut base = None;
        // the case, and its numbering where it is not the block's own
        let label = match n {
            Numbering::AsGiven => case.clone(),
            _ => format!("{case}/{}", n.label()),
        };
        for &t in threads {
            let m = measure(case, t, steps, p, n)?;
            let rate = (m.elements * steps) as f64 / m.seconds;
            let speedup = match base {
                None => {
                    base = Some(rate);
                    1.0
                }
                Some(b) => rate / b,
            };
            let shares: Vec<String> = m
                .stages
                .iter()
                .map(|(n, s)| format!("{n} {:.1} %", 100.0 * s))
                .collect();
            let roof = m.bandwidth / m.bytes_per_element;
            println!(
                "{label:<16} {:>4} {t:>7} {:>9} {:>9.3} {:>12.3} {:>8.2} {:>7.0} {:>10.1} {:>10.1} {:>6.0} %  {}",
                p.label(),
                m.elements,
                m.seconds,
                rate / 1e6,
                speedup,
                m.bytes_per_element,
                m.bandwidth / 1e9,
                roof / 1e6,
                100.0 * rate / roof,
                shares.join(", ")
            );
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_case_scene_parses() {
        for c in ["nh-1pt", "nh-fbar", "press", "ogden"] {
            for n in [Numbering::AsGiven, Numbering::Rcm] {
                let src = case_scene(c, Precision::F32, n).unwrap();
                let _: SceneSpec = toml::from_str(&src).unwrap();
                assert!(src.contains(&format!("numbering = \"{}\"", n.label())));
            }
        }
        assert!(case_scene("nope", Precision::F64, Numbering::AsGiven).is_err());
    }
}
