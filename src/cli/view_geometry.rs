//! The plan-view geometry of a model ([`surrogate::ViewGeometry`], `view.json`) from the
//! phantom it was trained on: outlines from [`phantom::plan_view`], ROI cells as the
//! convex hulls of the ROI elements' nodes in plan ([`surrogate::view::convex_hull`]), the
//! hand from the campaign's finger settings.
//!
//! `palpa campaign` writes `DIR/view.json` from the phantom it built; `palpa train` carries it
//! beside the model, or, for a dataset without one (made before it existed, such as the
//! committed default campaign), rebuilds the phantom from the manifest's `phantom.parameters`
//! (a few seconds) and checks that its ROI is the dataset's, element for element.

use phantom::{plan_view, Phantom, PLAN_STEP};
use solver::mesh::Mesh;
use std::path::{Path, PathBuf};
use surrogate::view::{convex_hull, Fingers, ViewGeometry, VIEW_FORMAT, VIEW_VERSION};

/// The geometry of a built phantom whose mesh is `mesh` (the phantom's own, or the simulation's
/// once a scene has taken it over), with the hand's `fingers`.
pub fn from_phantom(
    ph: &Phantom,
    mesh: &Mesh,
    fingers: Fingers,
    source: String,
) -> Result<ViewGeometry, String> {
    let plan = plan_view(ph, PLAN_STEP);
    let roi_cells = ph
        .roi
        .elements
        .iter()
        .map(|&e| {
            let nodes = mesh.elements.get(e as usize).ok_or_else(|| {
                format!(
                    "internal: ROI element {e} is not in the mesh of {} elements",
                    mesh.elements.len()
                )
            })?;
            let pts: Vec<[f64; 2]> = nodes
                .iter()
                .filter_map(|&n| mesh.nodes.get(n as usize).map(|q| [q[0], q[1]]))
                .collect();
            Ok(convex_hull(&pts))
        })
        .collect::<Result<Vec<_>, String>>()?;
    let view = ViewGeometry {
        format: VIEW_FORMAT.into(),
        version: VIEW_VERSION,
        source,
        torso: plan.torso,
        model_box: plan.model_box,
        liver: plan.liver,
        ribs: plan.ribs,
        roi_ids: ph.roi.elements.iter().map(|&e| e as i64).collect(),
        roi_cells,
        fingers,
        respiratory_phase: ph.params.respiratory_phase,
        max_liver_shift_m: ph.params.max_liver_shift,
    };
    view.validate()
        .map_err(|e| format!("internal: plan view: {e}"))?;
    Ok(view)
}

/// The hand of a palpation setup.
pub fn fingers(spacing_m: f64, diameter_m: f64) -> Fingers {
    Fingers {
        spacing_m,
        diameter_m,
        axis: [1.0, 0.0],
    }
}

/// The `view.json` of a dataset at `dataset` (a directory, or NAME.npz: NAME.view.json).
pub fn dataset_view_path(dataset: &Path) -> PathBuf {
    if dataset.extension().is_some_and(|e| e == "npz") {
        dataset.with_extension("view.json")
    } else {
        dataset.join("view.json")
    }
}

/// The geometry of the dataset at `dataset`: its `view.json` when it has one, else derived
/// from its manifest's phantom parameters; `None` when the manifest names no phantom (a
/// dataset not made by `palpa campaign`).
pub fn for_dataset(dataset: &Path) -> Result<Option<ViewGeometry>, String> {
    let vp = dataset_view_path(dataset);
    if vp.is_file() {
        return ViewGeometry::read(&vp).map(Some).map_err(|e| e.to_string());
    }
    let data = surrogate::Dataset::read(dataset).map_err(|e| e.to_string())?;
    let m = &data.manifest;
    let params = &m.phantom["parameters"];
    if params.is_null() {
        return Ok(None);
    }
    let centre = m.phantom["roi_center_m"].as_array().and_then(|a| {
        let v: Vec<f64> = a.iter().filter_map(|x| x.as_f64()).collect();
        (v.len() == 3).then(|| [v[0], v[1], v[2]])
    });
    let p = campaign::PhantomRecord::from_value(params)
        .and_then(|r| r.to_params(centre))
        .map_err(|e| format!("{}: manifest: {e}", dataset.display()))?;
    let ph = phantom::build(&p)
        .map_err(|e| format!("{}: rebuilding its phantom: {e}", dataset.display()))?;
    let ids: Vec<i64> = ph.roi.elements.iter().map(|&e| e as i64).collect();
    if ids.as_slice() != data.roi_ids.as_slice().unwrap_or(&[]) {
        return Err(format!(
            "{}: the phantom rebuilt from its manifest has another ROI ({} elements against \
             the dataset's {}): its view geometry cannot be derived",
            dataset.display(),
            ids.len(),
            data.roi_ids.len()
        ));
    }
    let settings = &m.solver["settings"];
    let d = Fingers::default();
    let f = fingers(
        settings["finger_spacing_m"].as_f64().unwrap_or(d.spacing_m),
        settings["finger_diameter_m"]
            .as_f64()
            .unwrap_or(d.diameter_m),
    );
    let source = format!(
        "phantom parameters of {} ({:?}, {:.1} mm voxels), rebuilt by palpa {}",
        dataset.display(),
        p.variant,
        p.voxel * 1e3,
        env!("CARGO_PKG_VERSION")
    );
    from_phantom(&ph, &ph.mesh, f, source).map(Some)
}
