//! The labelled voxel volume: dimensions, spacing, the index-to-world affine and one `u8`
//! label per voxel (0 = background).
//!
//! Storage order is x fastest (NIfTI / Fortran order): voxel `(i, j, k)` lives at
//! `i + nx (j + ny k)`. The affine maps a continuous voxel index `(i, j, k)` to world
//! coordinates in m, with integer indices at voxel *centres* (the NIfTI convention), so the
//! corners of voxel `(i, j, k)` sit at index coordinates `(i +- 1/2, j +- 1/2, k +- 1/2)`.

/// A 3-D volume of integer labels on a regular grid.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelVolume {
    /// Number of voxels along i, j, k.
    pub dims: [usize; 3],
    /// Voxel size along i, j, k (m); equal to the column norms of `affine`.
    pub spacing: [f64; 3],
    /// Row-major 4x4 affine, voxel index (at the voxel centre) -> world position (m).
    pub affine: [[f64; 4]; 4],
    /// One label per voxel, x fastest; 0 is background.
    pub labels: Vec<u8>,
}

impl LabelVolume {
    /// An all-background, axis-aligned volume; `origin` is the centre of voxel (0, 0, 0) (m).
    pub fn new(dims: [usize; 3], spacing: [f64; 3], origin: [f64; 3]) -> Self {
        let mut affine = [[0.0; 4]; 4];
        for a in 0..3 {
            affine[a][a] = spacing[a];
            affine[a][3] = origin[a];
        }
        affine[3][3] = 1.0;
        LabelVolume {
            dims,
            spacing,
            affine,
            labels: vec![0; dims[0] * dims[1] * dims[2]],
        }
    }

    /// A volume from a full affine (m) and its labels; spacing is derived from the affine.
    pub fn from_affine(
        dims: [usize; 3],
        affine: [[f64; 4]; 4],
        labels: Vec<u8>,
    ) -> Result<Self, String> {
        let Some(n) = dims.iter().try_fold(1usize, |n, &d| n.checked_mul(d)) else {
            return Err(format!(
                "dims {dims:?} give more voxels than fit in memory ({} x {} x {} overflows)",
                dims[0], dims[1], dims[2]
            ));
        };
        if labels.len() != n {
            return Err(format!(
                "label count {} does not match dims {:?}",
                labels.len(),
                dims
            ));
        }
        let mut spacing = [0.0; 3];
        for (c, s) in spacing.iter_mut().enumerate() {
            *s = (0..3)
                .map(|r| affine[r][c] * affine[r][c])
                .sum::<f64>()
                .sqrt();
        }
        if spacing.iter().any(|&s| !(s > 0.0)) {
            return Err(format!("degenerate affine: voxel spacing {spacing:?}"));
        }
        Ok(LabelVolume {
            dims,
            spacing,
            affine,
            labels,
        })
    }

    /// Total number of voxels.
    pub fn len(&self) -> usize {
        self.labels.len()
    }

    /// True when the volume has no voxels.
    pub fn is_empty(&self) -> bool {
        self.labels.is_empty()
    }

    /// Linear index of voxel (i, j, k).
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// Label of voxel (i, j, k).
    #[inline]
    pub fn get(&self, i: usize, j: usize, k: usize) -> u8 {
        self.labels[self.index(i, j, k)]
    }

    /// Label at signed indices; outside the volume is background.
    #[inline]
    pub fn get_or_bg(&self, i: isize, j: isize, k: isize) -> u8 {
        if i < 0 || j < 0 || k < 0 {
            return 0;
        }
        let (i, j, k) = (i as usize, j as usize, k as usize);
        if i >= self.dims[0] || j >= self.dims[1] || k >= self.dims[2] {
            return 0;
        }
        self.get(i, j, k)
    }

    /// Set the label of voxel (i, j, k).
    #[inline]
    pub fn set(&mut self, i: usize, j: usize, k: usize, l: u8) {
        let n = self.index(i, j, k);
        self.labels[n] = l;
    }

    /// World position (m) of the centre of voxel (0, 0, 0).
    pub fn origin(&self) -> [f64; 3] {
        [self.affine[0][3], self.affine[1][3], self.affine[2][3]]
    }

    /// World position (m) of a continuous voxel index.
    #[inline]
    pub fn index_to_world(&self, p: [f64; 3]) -> [f64; 3] {
        let a = &self.affine;
        [
            a[0][0] * p[0] + a[0][1] * p[1] + a[0][2] * p[2] + a[0][3],
            a[1][0] * p[0] + a[1][1] * p[1] + a[1][2] * p[2] + a[1][3],
            a[2][0] * p[0] + a[2][1] * p[1] + a[2][2] * p[2] + a[2][3],
        ]
    }

    /// World position (m) of the centre of voxel (i, j, k).
    pub fn voxel_center(&self, i: usize, j: usize, k: usize) -> [f64; 3] {
        self.index_to_world([i as f64, j as f64, k as f64])
    }

    /// Determinant of the affine's 3x3 part: negative for a left-handed (mirrored) grid.
    pub fn affine_det(&self) -> f64 {
        let a = &self.affine;
        a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])
    }

    /// Number of voxels carrying each label.
    pub fn label_counts(&self) -> [usize; 256] {
        let mut c = [0usize; 256];
        for &l in &self.labels {
            c[l as usize] += 1;
        }
        c
    }

    /// The sub-volume of voxels `lo <= (i, j, k) < hi` (clamped to the volume), with the
    /// affine shifted so world positions are unchanged.
    pub fn crop(&self, lo: [usize; 3], hi: [usize; 3]) -> LabelVolume {
        let lo = [
            lo[0].min(self.dims[0]),
            lo[1].min(self.dims[1]),
            lo[2].min(self.dims[2]),
        ];
        let hi = [
            hi[0].clamp(lo[0], self.dims[0]),
            hi[1].clamp(lo[1], self.dims[1]),
            hi[2].clamp(lo[2], self.dims[2]),
        ];
        let dims = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
        let mut labels = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
        for k in lo[2]..hi[2] {
            for j in lo[1]..hi[1] {
                let s = self.index(lo[0], j, k);
                labels.extend_from_slice(&self.labels[s..s + dims[0]]);
            }
        }
        let mut affine = self.affine;
        let o = self.index_to_world([lo[0] as f64, lo[1] as f64, lo[2] as f64]);
        for r in 0..3 {
            affine[r][3] = o[r];
        }
        LabelVolume {
            dims,
            spacing: self.spacing,
            affine,
            labels,
        }
    }

    /// Merge blocks of `f x f x f` voxels into one, taking the most frequent label of the
    /// block (background included; ties go to the smaller label). Partial blocks at the far
    /// faces count only the voxels they hold. The merged voxel's centre is the block centre.
    pub fn coarsen(&self, f: usize) -> LabelVolume {
        if f <= 1 {
            return self.clone();
        }
        let d = self.dims;
        let nd = [d[0].div_ceil(f), d[1].div_ceil(f), d[2].div_ceil(f)];
        let mut labels = vec![0u8; nd[0] * nd[1] * nd[2]];
        let mut hist = [0u32; 256];
        for kk in 0..nd[2] {
            for jj in 0..nd[1] {
                for ii in 0..nd[0] {
                    hist.iter_mut().for_each(|h| *h = 0);
                    for k in kk * f..((kk + 1) * f).min(d[2]) {
                        for j in jj * f..((jj + 1) * f).min(d[1]) {
                            for i in ii * f..((ii + 1) * f).min(d[0]) {
                                hist[self.get(i, j, k) as usize] += 1;
                            }
                        }
                    }
                    let mut best = 0usize;
                    for l in 1..256 {
                        if hist[l] > hist[best] {
                            best = l;
                        }
                    }
                    labels[ii + nd[0] * (jj + nd[1] * kk)] = best as u8;
                }
            }
        }
        let mut affine = self.affine;
        let c = (f as f64 - 1.0) / 2.0;
        let o = self.index_to_world([c, c, c]);
        for r in 0..3 {
            for col in 0..3 {
                affine[r][col] *= f as f64;
            }
            affine[r][3] = o[r];
        }
        let spacing = [
            self.spacing[0] * f as f64,
            self.spacing[1] * f as f64,
            self.spacing[2] * f as f64,
        ];
        LabelVolume {
            dims: nd,
            spacing,
            affine,
            labels,
        }
    }
}
