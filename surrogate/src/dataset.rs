//! The training dataset: an `.npz` of plain `.npy` arrays plus a JSON manifest.
//!
//! `numpy.load("dataset.npz")` reads it in one line: the archive is an uncompressed zip of
//! `.npy` files, written with `ndarray-npy`.
//!
//! | array | shape | dtype | meaning |
//! |---|---|---|---|
//! | `X` | n x c, c >= 3 | f64 | finger x [m], y [m], contact force [N]; optional further columns (e.g. time [s], depth [m], the respiratory phase) named in the manifest; a `phase` column is a model input ([`MODEL_INPUTS`]) |
//! | `Y` | n x R | f64 | maximum principal Cauchy stress of each ROI element [Pa] |
//! | `S` (optional) | n x R x 6 | f64 | full Cauchy stress per ROI element [Pa], Voigt order xx, yy, zz, xy, yz, zx |
//! | `roi_ids` | R | int64 | element ids of the ROI |
//! | `roi_centroids` | R x 3 | f64 | reference centroids of the ROI elements [m] |
//! | `location` | n | int64 | palpation location index of each sample (labels in the manifest) |
//! | `split` | n | uint8 (int8 accepted) | 0 = training, 1 = test (held-out location) |
//!
//! The manifest (`manifest.json` beside `dataset.npz` in a directory, or `NAME.json` beside
//! `NAME.npz`) holds the column names, units, location labels, and free-form solver and phantom
//! settings. Both files are written to a temporary name and renamed, so a reader never sees a
//! half-written dataset.

use crate::error::{Error, Result};
use ndarray::{Array1, Array2, Array3, ArrayBase, Axis, DataOwned, Dimension};
use ndarray_npy::{NpzReader, NpzWriter, ReadableElement};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufReader, BufWriter, Write};
use std::path::{Path, PathBuf};

/// Value of [`Manifest::format`].
pub const DATASET_FORMAT: &str = "palpa-dataset";
/// Current value of [`Manifest::version`].
pub const DATASET_VERSION: u32 = 1;

/// Sidecar JSON describing a dataset's arrays.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Manifest {
    /// Always `"palpa-dataset"`.
    pub format: String,
    /// Format version, currently 1.
    pub version: u32,
    /// Names of the columns of `X`; the first three are `x`, `y`, `force`.
    pub x_columns: Vec<String>,
    /// Unit of each quantity, e.g. `"x": "m"`, `"force": "N"`, `"Y": "Pa"`.
    pub units: BTreeMap<String, String>,
    /// Label of each location index (`location_labels[location[i]]`), e.g. `"grid-03"`, `"A"`.
    pub location_labels: Vec<String>,
    /// Voigt order of the components of `S`, when present.
    pub stress_components: Vec<String>,
    /// Solver version and settings (free-form, written by the campaign).
    pub solver: serde_json::Value,
    /// Phantom parameters (free-form, written by the campaign).
    pub phantom: serde_json::Value,
}

impl Default for Manifest {
    fn default() -> Self {
        let units = [
            ("x", "m"),
            ("y", "m"),
            ("force", "N"),
            ("time", "s"),
            ("depth", "m"),
            ("Y", "Pa"),
            ("S", "Pa"),
            ("roi_centroids", "m"),
        ]
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
        Manifest {
            format: DATASET_FORMAT.into(),
            version: DATASET_VERSION,
            x_columns: vec!["x".into(), "y".into(), "force".into()],
            units,
            location_labels: Vec::new(),
            stress_components: ["xx", "yy", "zz", "xy", "yz", "zx"]
                .iter()
                .map(|s| s.to_string())
                .collect(),
            solver: serde_json::Value::Null,
            phantom: serde_json::Value::Null,
        }
    }
}

/// A surrogate training dataset (see the module doc for shapes and units).
#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    /// Inputs, n x c: x [m], y [m], force [N], then optional columns.
    pub x: Array2<f64>,
    /// Targets, n x R: ROI maximum principal stress [Pa].
    pub y: Array2<f64>,
    /// Optional full stress tensors, n x R x 6 [Pa].
    pub stress: Option<Array3<f64>>,
    /// ROI element ids, R.
    pub roi_ids: Array1<i64>,
    /// ROI element centroids, R x 3 [m].
    pub roi_centroids: Array2<f64>,
    /// Location index of each sample, n.
    pub location: Array1<i64>,
    /// 0 = training sample, 1 = test sample, n.
    pub split: Array1<u8>,
    /// Column names, units, labels, settings.
    pub manifest: Manifest,
}

/// Whether a sample time `t` (s) is a multiple of `interval` to within `tolerance` (s).
pub fn on_stamp(t: f64, interval: f64, tolerance: f64) -> bool {
    (t - (t / interval).round() * interval).abs() <= tolerance
}

/// The `.npz` and manifest paths for `path`: `path` itself and `path` with extension `.json`
/// when it ends in `.npz`; otherwise `path/dataset.npz` and `path/manifest.json`.
pub fn dataset_paths(path: &Path) -> (PathBuf, PathBuf) {
    if path.extension().is_some_and(|e| e == "npz") {
        (path.to_path_buf(), path.with_extension("json"))
    } else {
        (path.join("dataset.npz"), path.join("manifest.json"))
    }
}

/// The inputs a model may take, in order: finger x [m], y [m], force [N] and, for a dataset
/// with a `phase` column (a respiratory campaign), the respiratory phase (0 exhalation .. 1
/// inspiration). A model takes the first three or all four.
pub const MODEL_INPUTS: [&str; 4] = ["x", "y", "force", "phase"];

impl Dataset {
    /// The columns of `X` a model trains on: x, y, force, and `phase` when the dataset has one
    /// ([`MODEL_INPUTS`]).
    pub fn model_input_columns(&self) -> Vec<usize> {
        let mut c = vec![0, 1, 2];
        c.extend(self.manifest.x_columns.iter().position(|n| n == "phase"));
        c
    }

    /// The dataset without the `X` column `name` (unchanged when it has none).
    pub fn without_column(mut self, name: &str) -> Dataset {
        if let Some(k) = self.manifest.x_columns.iter().position(|c| c == name) {
            let keep: Vec<usize> = (0..self.x.ncols()).filter(|&c| c != k).collect();
            self.x = self.x.select(Axis(1), &keep);
            self.manifest.x_columns.remove(k);
        }
        self
    }

    /// The model inputs of every row (n x 3, or n x 4 with a phase; [`Dataset::model_input_columns`]).
    pub fn model_inputs(&self) -> Array2<f64> {
        self.x.select(Axis(1), &self.model_input_columns())
    }

    /// Number of samples n.
    pub fn n_samples(&self) -> usize {
        self.x.nrows()
    }

    /// Number of ROI elements R.
    pub fn n_roi(&self) -> usize {
        self.y.ncols()
    }

    /// Row indices of the training or test samples.
    pub fn rows_with_split(&self, split: crate::Split) -> Vec<usize> {
        (0..self.n_samples())
            .filter(|&i| self.split[i] == split.code())
            .collect()
    }

    /// The dataset with fewer training samples (test samples untouched): only the first
    /// `first_locations` training locations in the order they appear (a campaign's order, so
    /// the first n points of a Sobol design), and only samples at multiples of `interval` (s;
    /// [`on_stamp`]). An error names a selection that keeps no training sample.
    pub fn select_training(
        &self,
        first_locations: Option<usize>,
        interval: Option<f64>,
    ) -> Result<Dataset> {
        let order = self.training_location_order();
        let keep_loc: Vec<i64> = match first_locations {
            Some(n) if n > order.len() => {
                return Err(Error::invalid(
                    "train locations",
                    format!(
                        "asked for the first {n}, the dataset has {} training locations",
                        order.len()
                    ),
                ))
            }
            Some(n) => order[..n].to_vec(),
            None => order,
        };
        let time_col = self.manifest.x_columns.iter().position(|c| c == "time");
        if let Some(dt) = interval {
            if !(dt > 0.0 && dt.is_finite()) {
                return Err(Error::invalid(
                    "train interval",
                    format!("{dt} s is not a positive time"),
                ));
            }
            if time_col.is_none() {
                return Err(Error::invalid(
                    "train interval",
                    "the dataset has no `time` column",
                ));
            }
        }
        let tol = interval.map(|dt| self.stamp_tolerance(dt));
        let on_stamp = |i: usize| match (interval, time_col, tol) {
            (Some(dt), Some(c), Some(tol)) => on_stamp(self.x[(i, c)], dt, tol),
            _ => true,
        };
        self.keep_training("train selection", |i| {
            keep_loc.contains(&self.location[i]) && on_stamp(i)
        })
    }

    /// The dataset without the training samples of the locations labelled `labels` (test
    /// samples untouched): what one run, or a few, does to a model, e.g. a batch's point that
    /// lowers the Fit of a held-out location beside it (docs/surrogate.md). An error names a
    /// label that is not a training location here, and a selection that keeps no training sample.
    pub fn without_training_locations(&self, labels: &[String]) -> Result<Dataset> {
        let order = self.training_location_order();
        let mut drop: Vec<i64> = Vec::new();
        for l in labels {
            let bad = |why: String| Error::invalid("leave-out", why);
            if l.trim().is_empty() {
                return Err(bad("an empty label".into()));
            }
            let id = order
                .iter()
                .find(|&&id| self.location_label(id) == *l)
                .ok_or_else(|| bad(format!("`{l}` is not a training location of the selection")))?;
            if drop.contains(id) {
                return Err(bad(format!("`{l}` is given twice")));
            }
            drop.push(*id);
        }
        self.keep_training("leave-out", |i| !drop.contains(&self.location[i]))
    }

    /// The dataset with the test samples and the training samples `i` for which `keep(i)`
    /// holds, in order; an error (of `what`) when no training sample is kept.
    fn keep_training(&self, what: &str, keep: impl Fn(usize) -> bool) -> Result<Dataset> {
        let rows: Vec<usize> = (0..self.n_samples())
            .filter(|&i| self.split[i] != crate::Split::Train.code() || keep(i))
            .collect();
        if !rows
            .iter()
            .any(|&i| self.split[i] == crate::Split::Train.code())
        {
            return Err(Error::invalid(what, "keeps no training sample"));
        }
        Ok(Dataset {
            x: self.x.select(Axis(0), &rows),
            y: self.y.select(Axis(0), &rows),
            stress: self.stress.as_ref().map(|s| s.select(Axis(0), &rows)),
            roi_ids: self.roi_ids.clone(),
            roi_centroids: self.roi_centroids.clone(),
            location: self.location.select(Axis(0), &rows),
            split: self.split.select(Axis(0), &rows),
            manifest: self.manifest.clone(),
        })
    }

    /// The training locations in the order their first sample appears (a campaign's order).
    pub fn training_location_order(&self) -> Vec<i64> {
        let mut order: Vec<i64> = Vec::new();
        for i in self.rows_with_split(crate::Split::Train) {
            if !order.contains(&self.location[i]) {
                order.push(self.location[i]);
            }
        }
        order
    }

    /// The tolerance (s) within which a sample is taken to lie on a stamp of `interval`: a
    /// quarter of the samples' own spacing (the smallest gap between two times of one
    /// location), at most a tenth of the interval. A campaign samples at the step nearest
    /// each stamp, a step (microseconds) off; a neighbouring sample lies a spacing away.
    pub fn stamp_tolerance(&self, interval: f64) -> f64 {
        let Some(c) = self.manifest.x_columns.iter().position(|c| c == "time") else {
            return 0.1 * interval;
        };
        let mut by_loc: BTreeMap<i64, Vec<f64>> = BTreeMap::new();
        for i in 0..self.n_samples() {
            by_loc
                .entry(self.location[i])
                .or_default()
                .push(self.x[(i, c)]);
        }
        let mut gap = f64::INFINITY;
        for t in by_loc.values_mut() {
            t.sort_by(f64::total_cmp);
            for w in t.windows(2) {
                let d = w[1] - w[0];
                if d > 0.0 {
                    gap = gap.min(d);
                }
            }
        }
        (0.25 * gap).min(0.1 * interval)
    }

    /// Label of location `id`: the manifest's label, or `loc-ID` when it has none.
    pub fn location_label(&self, id: i64) -> String {
        usize::try_from(id)
            .ok()
            .and_then(|i| self.manifest.location_labels.get(i).cloned())
            .unwrap_or_else(|| format!("loc-{id}"))
    }

    /// Checks shapes, dtypes' ranges and finiteness; the error names the array at fault.
    pub fn validate(&self) -> Result<()> {
        let n = self.x.nrows();
        let r = self.y.ncols();
        if self.x.ncols() < 3 {
            return Err(Error::invalid(
                "X",
                format!(
                    "needs at least 3 columns (x, y, force), has {}",
                    self.x.ncols()
                ),
            ));
        }
        if self.manifest.x_columns.len() != self.x.ncols() {
            return Err(Error::invalid(
                "manifest.x_columns",
                format!(
                    "names {} columns but X has {}",
                    self.manifest.x_columns.len(),
                    self.x.ncols()
                ),
            ));
        }
        if r == 0 {
            return Err(Error::invalid("Y", "has no ROI columns"));
        }
        let rows = [
            ("Y", self.y.nrows()),
            ("location", self.location.len()),
            ("split", self.split.len()),
        ];
        for (name, m) in rows {
            if m != n {
                return Err(Error::invalid(name, format!("has {m} rows but X has {n}")));
            }
        }
        if let Some(s) = &self.stress {
            if s.dim() != (n, r, 6) {
                return Err(Error::invalid(
                    "S",
                    format!("shape {:?}, expected ({n}, {r}, 6)", s.dim()),
                ));
            }
            if s.iter().any(|v| !v.is_finite()) {
                return Err(Error::invalid("S", "contains a non-finite value"));
            }
        }
        if self.roi_ids.len() != r {
            return Err(Error::invalid(
                "roi_ids",
                format!("has {} entries but Y has {r} columns", self.roi_ids.len()),
            ));
        }
        if self.roi_centroids.dim() != (r, 3) {
            return Err(Error::invalid(
                "roi_centroids",
                format!("shape {:?}, expected ({r}, 3)", self.roi_centroids.dim()),
            ));
        }
        for (name, a) in [
            ("X", &self.x),
            ("Y", &self.y),
            ("roi_centroids", &self.roi_centroids),
        ] {
            if let Some(pos) = a.iter().position(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    name,
                    format!("non-finite value at flat index {pos}"),
                ));
            }
        }
        if let Some(i) = self
            .split
            .iter()
            .position(|&s| crate::Split::from_code(s).is_none())
        {
            return Err(Error::invalid(
                "split",
                format!(
                    "entry {i} is {}, expected 0 (train) or 1 (test)",
                    self.split[i]
                ),
            ));
        }
        if let Some(i) = self.location.iter().position(|&l| l < 0) {
            return Err(Error::invalid(
                "location",
                format!("entry {i} is negative ({})", self.location[i]),
            ));
        }
        Ok(())
    }

    /// Writes `dataset.npz` + `manifest.json` (or `NAME.npz` + `NAME.json`, see [`dataset_paths`]),
    /// each through a temporary file and a rename. Creates the directory if needed.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<()> {
        self.validate()?;
        let (npz, json) = dataset_paths(path.as_ref());
        if let Some(dir) = npz.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
        }
        write_atomic(&npz, |file| {
            let mut w = NpzWriter::new(BufWriter::new(file));
            let fail = |name: &str, e: ndarray_npy::WriteNpzError| {
                Error::format(&npz, format!("writing array {name}: {e}"))
            };
            w.add_array("X", &self.x).map_err(|e| fail("X", e))?;
            w.add_array("Y", &self.y).map_err(|e| fail("Y", e))?;
            if let Some(s) = &self.stress {
                w.add_array("S", s).map_err(|e| fail("S", e))?;
            }
            w.add_array("roi_ids", &self.roi_ids)
                .map_err(|e| fail("roi_ids", e))?;
            w.add_array("roi_centroids", &self.roi_centroids)
                .map_err(|e| fail("roi_centroids", e))?;
            w.add_array("location", &self.location)
                .map_err(|e| fail("location", e))?;
            w.add_array("split", &self.split)
                .map_err(|e| fail("split", e))?;
            let mut inner = w.finish().map_err(|e| fail("(archive)", e))?;
            inner.flush().map_err(|e| Error::io(&npz, e))?;
            Ok(())
        })?;
        let text = serde_json::to_string_pretty(&self.manifest)
            .map_err(|e| Error::format(&json, e.to_string()))?;
        write_atomic(&json, |mut file| {
            file.write_all(text.as_bytes())
                .map_err(|e| Error::io(&json, e))
        })
    }

    /// Reads a dataset written by [`Dataset::write`] (or by numpy with the same array names),
    /// and validates it.
    pub fn read(path: impl AsRef<Path>) -> Result<Dataset> {
        let (npz, json) = dataset_paths(path.as_ref());
        let text = std::fs::read_to_string(&json).map_err(|e| Error::io(&json, e))?;
        let manifest: Manifest =
            serde_json::from_str(&text).map_err(|e| Error::format(&json, e.to_string()))?;
        if manifest.format != DATASET_FORMAT {
            return Err(Error::format(
                &json,
                format!(
                    "format is {:?}, expected {DATASET_FORMAT:?}",
                    manifest.format
                ),
            ));
        }
        if manifest.version > DATASET_VERSION {
            return Err(Error::format(
                &json,
                format!(
                    "version {} is newer than this reader ({DATASET_VERSION})",
                    manifest.version
                ),
            ));
        }
        let file = File::open(&npz).map_err(|e| Error::io(&npz, e))?;
        let mut r = NpzReader::new(BufReader::new(file))
            .map_err(|e| Error::format(&npz, format!("not an npz archive: {e}")))?;
        let names = r.names().map_err(|e| Error::format(&npz, e.to_string()))?;
        let has = |n: &str| names.iter().any(|m| m == n);
        let x: Array2<f64> = get(&mut r, &npz, "X")?;
        let y: Array2<f64> = get(&mut r, &npz, "Y")?;
        let stress: Option<Array3<f64>> = if has("S") {
            Some(get(&mut r, &npz, "S")?)
        } else {
            None
        };
        let roi_ids: Array1<i64> = get_int(&mut r, &npz, "roi_ids")?;
        let roi_centroids: Array2<f64> = get(&mut r, &npz, "roi_centroids")?;
        let location: Array1<i64> = get_int(&mut r, &npz, "location")?;
        let split: Array1<u8> = get_split(&mut r, &npz)?;
        let d = Dataset {
            x,
            y,
            stress,
            roi_ids,
            roi_centroids,
            location,
            split,
            manifest,
        };
        d.validate()
            .map_err(|e| Error::format(&npz, e.to_string()))?;
        Ok(d)
    }
}

fn get<S, D>(r: &mut NpzReader<BufReader<File>>, path: &Path, name: &str) -> Result<ArrayBase<S, D>>
where
    S: DataOwned,
    S::Elem: ReadableElement,
    D: Dimension,
{
    r.by_name(name)
        .map_err(|e| Error::format(path, format!("array {name}: {e}")))
}

/// Integer arrays: int64 preferred; int32 accepted.
fn get_int(r: &mut NpzReader<BufReader<File>>, path: &Path, name: &str) -> Result<Array1<i64>> {
    match get::<_, ndarray::Ix1>(r, path, name) {
        Ok(a) => Ok(a),
        Err(first) => get::<ndarray::OwnedRepr<i32>, ndarray::Ix1>(r, path, name)
            .map(|a| a.mapv(i64::from))
            .map_err(|_| first),
    }
}

/// `split`: uint8 preferred; int8 and int64 accepted.
fn get_split(r: &mut NpzReader<BufReader<File>>, path: &Path) -> Result<Array1<u8>> {
    let name = "split";
    if let Ok(a) = get::<ndarray::OwnedRepr<u8>, ndarray::Ix1>(r, path, name) {
        return Ok(a);
    }
    let wide: Array1<i64> = match get::<ndarray::OwnedRepr<i8>, ndarray::Ix1>(r, path, name) {
        Ok(a) => a.mapv(i64::from),
        Err(_) => get::<ndarray::OwnedRepr<i64>, ndarray::Ix1>(r, path, name)
            .map_err(|_| Error::format(path, "array split: expected uint8, int8 or int64"))?,
    };
    if let Some(i) = wide.iter().position(|&v| !(0..=1).contains(&v)) {
        return Err(Error::format(
            path,
            format!("array split: entry {i} is {}, expected 0 or 1", wide[i]),
        ));
    }
    Ok(wide.mapv(|v| v as u8))
}

/// Writes `path` by calling `fill` on `path.tmp`, syncing, and renaming over `path`.
pub(crate) fn write_atomic(path: &Path, fill: impl FnOnce(File) -> Result<()>) -> Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    let file = File::create(&tmp).map_err(|e| Error::io(&tmp, e))?;
    let result = fill(file.try_clone().map_err(|e| Error::io(&tmp, e))?)
        .and_then(|_| file.sync_all().map_err(|e| Error::io(&tmp, e)));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    std::fs::rename(&tmp, path).map_err(|e| Error::io(path, e))
}
