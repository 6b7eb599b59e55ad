//! Topological clean-up of a label volume before meshing.
//!
//! 1. **Islands per label**: 6-connected components of one label with fewer than
//!    `min_island_voxels` voxels take the most frequent other label among their 6-neighbours
//!    (possibly background), so a speck of rib inside flesh becomes flesh.
//! 2. **Foreground components**: 6-connected components of the foreground (label != 0) that
//!    are not the largest (or, if `keep_largest` is off, smaller than `min_island_voxels`)
//!    are removed.
//! 3. **Non-manifold connections**: voxels joined only along an edge or at a corner give a
//!    mesh whose elements hinge on one edge or node. At every grid vertex the 2x2x2 block of
//!    voxels around it is tested: the boundary surface is a 2-manifold there iff both the
//!    foreground and the background voxels of the block are each 6-connected within the block
//!    (the usual digital-topology test, e.g. Lachaud & Montanvert, "Continuous analogs of
//!    digital boundaries", 2000). A split foreground is repaired by removing the voxels of the
//!    smaller part(s); a split background by filling the smaller part(s) with the most frequent
//!    neighbouring label. Sweeps repeat until nothing changes (at most `max_sweeps`).
//!
//! Every pass scans voxels in storage order, so the result is deterministic.

use std::collections::VecDeque;

use super::LabelVolume;

/// What the clean-up changed.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct CleanupReport {
    /// Voxels relabelled because their label's component was too small.
    pub island_voxels_relabelled: usize,
    /// Voxels removed with small or detached foreground components.
    pub detached_voxels_removed: usize,
    /// Voxels removed to cut edge- or corner-only connections.
    pub nonmanifold_removed: usize,
    /// Background voxels filled to close edge- or corner-only gaps.
    pub nonmanifold_filled: usize,
    /// Non-manifold vertices left after the last sweep (0 when converged).
    pub nonmanifold_left: usize,
}

const N6: [[isize; 3]; 6] = [
    [-1, 0, 0],
    [1, 0, 0],
    [0, -1, 0],
    [0, 1, 0],
    [0, 0, -1],
    [0, 0, 1],
];

fn neighbours6(vol: &LabelVolume, n: usize) -> impl Iterator<Item = usize> + '_ {
    let [nx, ny, nz] = vol.dims;
    let i = n % nx;
    let j = (n / nx) % ny;
    let k = n / (nx * ny);
    N6.iter().filter_map(move |d| {
        let (a, b, c) = (i as isize + d[0], j as isize + d[1], k as isize + d[2]);
        if a < 0 || b < 0 || c < 0 || a >= nx as isize || b >= ny as isize || c >= nz as isize {
            None
        } else {
            Some(a as usize + nx * (b as usize + ny * c as usize))
        }
    })
}

/// Most frequent label among the 6-neighbours of voxel `n` (outside counts as background),
/// excluding `exclude`; ties go to the smaller label.
fn majority_neighbour(vol: &LabelVolume, n: usize, exclude: Option<u8>) -> u8 {
    let mut hist = [0u8; 256];
    let [nx, ny, nz] = vol.dims;
    let (i, j, k) = (n % nx, (n / nx) % ny, n / (nx * ny));
    let on_border = i == 0 || j == 0 || k == 0 || i + 1 == nx || j + 1 == ny || k + 1 == nz;
    let mut outside = 0u8;
    if on_border {
        outside = 6 - neighbours6(vol, n).count() as u8;
    }
    hist[0] += outside;
    for m in neighbours6(vol, n) {
        hist[vol.labels[m] as usize] += 1;
    }
    let mut best: Option<usize> = None;
    for l in 0..256 {
        if Some(l as u8) == exclude || hist[l] == 0 {
            continue;
        }
        if best.is_none_or(|b| hist[l] > hist[b]) {
            best = Some(l);
        }
    }
    best.map(|b| b as u8).unwrap_or(0)
}

/// 6-connected components of voxels satisfying `pred`; returns (component id per voxel,
/// component sizes), ids in order of first voxel.
fn components(vol: &LabelVolume, pred: impl Fn(u8, u8) -> bool) -> (Vec<u32>, Vec<usize>) {
    let mut comp = vec![u32::MAX; vol.len()];
    let mut sizes = Vec::new();
    let mut queue = VecDeque::new();
    for s in 0..vol.len() {
        if comp[s] != u32::MAX || !pred(vol.labels[s], vol.labels[s]) {
            continue;
        }
        let id = sizes.len() as u32;
        let mut size = 0;
        comp[s] = id;
        queue.push_back(s);
        while let Some(n) = queue.pop_front() {
            size += 1;
            for m in neighbours6(vol, n) {
                if comp[m] == u32::MAX && pred(vol.labels[s], vol.labels[m]) {
                    comp[m] = id;
                    queue.push_back(m);
                }
            }
        }
        sizes.push(size);
    }
    (comp, sizes)
}

/// Relabel components of a single label smaller than `min_voxels`: the whole component takes
/// the most frequent label found around it (outside the volume counts as background).
pub fn remove_label_islands(vol: &mut LabelVolume, min_voxels: usize) -> usize {
    if min_voxels <= 1 {
        return 0;
    }
    let (comp, sizes) = components(vol, |seed, l| l != 0 && l == seed);
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); sizes.len()];
    for (n, &c) in comp.iter().enumerate() {
        if c != u32::MAX && sizes[c as usize] < min_voxels {
            members[c as usize].push(n);
        }
    }
    let mut changed = 0;
    for (c, list) in members.iter().enumerate() {
        if list.is_empty() {
            continue;
        }
        let own = vol.labels[list[0]];
        let mut hist = [0usize; 256];
        for &n in list {
            hist[0] += 6 - neighbours6(vol, n).count();
            for m in neighbours6(vol, n) {
                if comp[m] != c as u32 {
                    hist[vol.labels[m] as usize] += 1;
                }
            }
        }
        let mut best = 0usize;
        for l in 1..256 {
            if l as u8 != own && hist[l] > hist[best] {
                best = l;
            }
        }
        for &n in list {
            vol.labels[n] = best as u8;
        }
        changed += list.len();
    }
    changed
}

/// Remove detached foreground components (all but the largest if `keep_largest`, else those
/// smaller than `min_voxels`).
pub fn remove_detached(vol: &mut LabelVolume, min_voxels: usize, keep_largest: bool) -> usize {
    let (comp, sizes) = components(vol, |_, l| l != 0);
    if sizes.is_empty() {
        return 0;
    }
    let largest = (0..sizes.len())
        .max_by_key(|&c| (sizes[c], usize::MAX - c))
        .unwrap_or(0);
    let mut removed = 0;
    for n in 0..vol.len() {
        let c = comp[n];
        if c == u32::MAX {
            continue;
        }
        let drop = if keep_largest {
            c as usize != largest
        } else {
            sizes[c as usize] < min_voxels
        };
        if drop {
            vol.labels[n] = 0;
            removed += 1;
        }
    }
    removed
}

/// Components of the set bits of an 8-bit 2x2x2 block mask (bit b = voxel with offsets
/// (b & 1, b >> 1 & 1, b >> 2 & 1)); 6-adjacency = masks differing in one bit.
fn block_components(mask: u8) -> Vec<u8> {
    let mut comps = Vec::new();
    let mut left = mask;
    while left != 0 {
        let first = left.trailing_zeros() as u8;
        let mut c = 1u8 << first;
        loop {
            let mut grown = c;
            for b in 0..8u8 {
                if c & (1 << b) != 0 {
                    for d in [1u8, 2, 4] {
                        let nb = b ^ d;
                        if mask & (1 << nb) != 0 {
                            grown |= 1 << nb;
                        }
                    }
                }
            }
            if grown == c {
                break;
            }
            c = grown;
        }
        comps.push(c);
        left &= !c;
    }
    comps
}

/// True when a 2x2x2 foreground mask gives a manifold boundary at the shared vertex.
pub fn block_is_manifold(mask: u8) -> bool {
    mask == 0
        || mask == 255
        || (block_components(mask).len() == 1 && block_components(!mask).len() == 1)
}

/// Repair edge- and corner-only connections; returns (removed, filled, left).
pub fn fix_nonmanifold(vol: &mut LabelVolume, max_sweeps: usize) -> (usize, usize, usize) {
    let table: Vec<bool> = (0..=255u8).map(block_is_manifold).collect();
    let [nx, ny, nz] = vol.dims;
    let (mut removed, mut filled) = (0, 0);
    for _ in 0..max_sweeps.max(1) {
        let mut changed = false;
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    // block voxels: (i-1+dx, j-1+dy, k-1+dz)
                    let vox = |b: u8| -> (isize, isize, isize) {
                        (
                            i as isize - 1 + (b & 1) as isize,
                            j as isize - 1 + ((b >> 1) & 1) as isize,
                            k as isize - 1 + ((b >> 2) & 1) as isize,
                        )
                    };
                    let mut mask = 0u8;
                    for b in 0..8u8 {
                        let (a, bb, c) = vox(b);
                        if vol.get_or_bg(a, bb, c) != 0 {
                            mask |= 1 << b;
                        }
                    }
                    if table[mask as usize] {
                        continue;
                    }
                    let inside = |a: isize, b: isize, c: isize| {
                        a >= 0
                            && b >= 0
                            && c >= 0
                            && a < nx as isize
                            && b < ny as isize
                            && c < nz as isize
                    };
                    let fg = block_components(mask);
                    if fg.len() > 1 {
                        // keep the component with most voxels, then with most volume neighbours
                        let score = |c: u8| -> (u32, usize) {
                            let mut nb = 0;
                            for b in 0..8u8 {
                                if c & (1 << b) != 0 {
                                    let (a, bb, cc) = vox(b);
                                    let n = vol.index(a as usize, bb as usize, cc as usize);
                                    nb +=
                                        neighbours6(vol, n).filter(|&m| vol.labels[m] != 0).count();
                                }
                            }
                            (c.count_ones(), nb)
                        };
                        let keep = (0..fg.len())
                            .max_by_key(|&q| (score(fg[q]), usize::MAX - q))
                            .unwrap_or(0);
                        for (q, &c) in fg.iter().enumerate() {
                            if q == keep {
                                continue;
                            }
                            for b in 0..8u8 {
                                if c & (1 << b) != 0 {
                                    let (a, bb, cc) = vox(b);
                                    vol.set(a as usize, bb as usize, cc as usize, 0);
                                    removed += 1;
                                }
                            }
                        }
                        changed = true;
                    } else {
                        let bg = block_components(!mask);
                        let keep = (0..bg.len())
                            .max_by_key(|&q| (bg[q].count_ones(), usize::MAX - q))
                            .unwrap_or(0);
                        let mut did = false;
                        for (q, &c) in bg.iter().enumerate() {
                            if q == keep {
                                continue;
                            }
                            for b in 0..8u8 {
                                if c & (1 << b) != 0 {
                                    let (a, bb, cc) = vox(b);
                                    if inside(a, bb, cc) {
                                        let n = vol.index(a as usize, bb as usize, cc as usize);
                                        let l = majority_neighbour(vol, n, Some(0));
                                        vol.labels[n] = l;
                                        filled += 1;
                                        did = true;
                                    }
                                }
                            }
                        }
                        changed |= did;
                    }
                }
            }
        }
        if !changed {
            break;
        }
    }
    let left = count_nonmanifold(vol, &table);
    (removed, filled, left)
}

/// Number of grid vertices whose 2x2x2 block is not manifold.
fn count_nonmanifold(vol: &LabelVolume, table: &[bool]) -> usize {
    let [nx, ny, nz] = vol.dims;
    let mut count = 0;
    for k in 0..=nz as isize {
        for j in 0..=ny as isize {
            for i in 0..=nx as isize {
                let mut mask = 0u8;
                for b in 0..8u8 {
                    let (a, bb, c) = (
                        i - 1 + (b & 1) as isize,
                        j - 1 + ((b >> 1) & 1) as isize,
                        k - 1 + ((b >> 2) & 1) as isize,
                    );
                    if vol.get_or_bg(a, bb, c) != 0 {
                        mask |= 1 << b;
                    }
                }
                if !table[mask as usize] {
                    count += 1;
                }
            }
        }
    }
    count
}

/// Run the whole clean-up.
pub fn cleanup(
    vol: &mut LabelVolume,
    min_island_voxels: usize,
    keep_largest: bool,
    fix_nm: bool,
) -> CleanupReport {
    let mut r = CleanupReport {
        island_voxels_relabelled: remove_label_islands(vol, min_island_voxels),
        ..Default::default()
    };
    r.detached_voxels_removed = remove_detached(vol, min_island_voxels, keep_largest);
    if fix_nm {
        let (rem, fil, left) = fix_nonmanifold(vol, 20);
        r.nonmanifold_removed = rem;
        r.nonmanifold_filled = fil;
        r.nonmanifold_left = left;
        r.detached_voxels_removed += remove_detached(vol, min_island_voxels, keep_largest);
    }
    r
}
