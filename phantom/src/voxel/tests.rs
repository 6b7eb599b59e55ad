use super::*;

fn no_smooth() -> MeshOptions {
    MeshOptions {
        smoothing: SmoothOptions {
            iterations: 0,
            ..Default::default()
        },
        ..Default::default()
    }
}

fn map12() -> LabelMap {
    LabelMap::new().with(1, "a").with(2, "b")
}

#[test]
fn two_parts_share_nodes_and_counts_are_exact() {
    // a 3 x 2 x 2 block: label 1 for i < 2, label 2 for i = 2
    let mut v = LabelVolume::new([3, 2, 2], [1e-3; 3], [0.0; 3]);
    for k in 0..2 {
        for j in 0..2 {
            for i in 0..3 {
                v.set(i, j, k, if i < 2 { 1 } else { 2 });
            }
        }
    }
    let opts = MeshOptions {
        min_island_voxels: 1,
        ..no_smooth()
    };
    let (m, q) = mesh_volume(&v, &map12(), &opts).unwrap();
    assert_eq!(m.n_elements(), 12);
    assert_eq!(m.n_nodes(), 4 * 3 * 3); // shared across the interface
    assert_eq!(
        q.part_counts,
        vec![("a".to_string(), 8), ("b".to_string(), 4)]
    );
    assert!((q.min_scaled_jacobian - 1.0).abs() < 1e-12);
    // element volume = 1 mm^3: corner Jacobian of a cube of side h is h^3
    assert!((q.min_corner_jacobian - 1e-9).abs() < 1e-18);
    let (lo, hi) = m.bounds();
    assert!((lo[0] + 0.5e-3).abs() < 1e-12 && (hi[0] - 2.5e-3).abs() < 1e-12);
}

#[test]
fn unmapped_label_is_an_error() {
    let mut v = LabelVolume::new([2, 2, 2], [1e-3; 3], [0.0; 3]);
    v.labels.iter_mut().for_each(|l| *l = 3);
    assert!(mesh_volume(&v, &map12(), &no_smooth()).is_err());
}

#[test]
fn islands_and_detached_pieces_are_removed() {
    let mut v = LabelVolume::new([10, 10, 10], [1e-3; 3], [0.0; 3]);
    for k in 1..9 {
        for j in 1..9 {
            for i in 1..6 {
                v.set(i, j, k, 1);
            }
        }
    }
    v.set(3, 4, 4, 2); // one-voxel island of label 2 inside label 1
    v.set(8, 8, 8, 1); // detached voxel (corner-touching nothing)
    let rep = cleanup(&mut v, 8, true, true);
    assert_eq!(v.get(3, 4, 4), 1);
    assert_eq!(v.get(8, 8, 8), 0);
    // the island and the detached voxel (a one-voxel component of label 1)
    assert_eq!(rep.island_voxels_relabelled, 2);
}

#[test]
fn edge_and_corner_only_connections_are_cut() {
    // two 3x3x3 cubes touching along an edge, and a third touching the first at a corner
    let mut v = LabelVolume::new([12, 12, 12], [1e-3; 3], [0.0; 3]);
    let mut cube = |o: [usize; 3]| {
        for k in 0..3 {
            for j in 0..3 {
                for i in 0..3 {
                    v.set(o[0] + i, o[1] + j, o[2] + k, 1);
                }
            }
        }
    };
    cube([1, 1, 1]);
    cube([4, 4, 1]); // shares the edge x = 4, y = 4 with the first
    cube([4, 4, 4]); // face-connected to the second, corner-touching the first at (4,4,4)
    let (rem, fil, left) = fix_nonmanifold(&mut v, 20);
    assert_eq!(left, 0, "removed {rem} filled {fil}");
    // every 2x2x2 block is now manifold
    let [nx, ny, nz] = v.dims;
    for k in 0..=nz as isize {
        for j in 0..=ny as isize {
            for i in 0..=nx as isize {
                let mut mask = 0u8;
                for b in 0..8u8 {
                    if v.get_or_bg(
                        i - 1 + (b & 1) as isize,
                        j - 1 + ((b >> 1) & 1) as isize,
                        k - 1 + ((b >> 2) & 1) as isize,
                    ) != 0
                    {
                        mask |= 1 << b;
                    }
                }
                assert!(block_is_manifold(mask));
            }
        }
    }
    assert!(!block_is_manifold(0b1000_0001)); // corner-only
    assert!(!block_is_manifold(0b0000_1001)); // edge-only
    assert!(block_is_manifold(0b0000_0011));
}

fn sphere(n: usize, h: f64, r: f64) -> LabelVolume {
    let c = (n as f64 - 1.0) / 2.0;
    let mut v = LabelVolume::new([n; 3], [h; 3], [-c * h; 3]);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = v.voxel_center(i, j, k);
                let d = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
                if d <= r {
                    v.set(i, j, k, if d <= 0.5 * r { 2 } else { 1 });
                }
            }
        }
    }
    v
}

fn rms_radius_error(m: &solver::mesh::Mesh, r: f64) -> f64 {
    let s = &m.node_sets["surface"];
    let e2: f64 = s
        .iter()
        .map(|&n| {
            let p = m.nodes[n as usize];
            ((p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt() - r).powi(2)
        })
        .sum();
    (e2 / s.len() as f64).sqrt()
}

#[test]
fn smoothing_rounds_a_voxel_sphere_and_keeps_jacobians_positive() {
    let (h, r) = (1e-3, 8.4e-3);
    let v = sphere(21, h, r);
    let (raw, q0) = mesh_volume(&v, &map12(), &no_smooth()).unwrap();
    let (sm, q1) = mesh_volume(&v, &map12(), &MeshOptions::default()).unwrap();
    assert_eq!(raw.n_elements(), sm.n_elements());
    let (e0, e1) = (rms_radius_error(&raw, r), rms_radius_error(&sm, r));
    // default limits (scaled Jacobian >= 0.3, V/A_max >= 0.6 of its voxel value): rounder
    assert!(e1 < 0.9 * e0, "rms radius error {e0:.3e} -> {e1:.3e}");
    // looser time-step limit: much rounder
    let loose = MeshOptions {
        smoothing: SmoothOptions {
            min_length_ratio: 0.3,
            ..Default::default()
        },
        ..Default::default()
    };
    let (sl, ql) = mesh_volume(&v, &map12(), &loose).unwrap();
    let e2 = rms_radius_error(&sl, r);
    assert!(
        e2 < 0.6 * e0,
        "rms radius error {e0:.3e} -> {e2:.3e} (loose)"
    );
    assert_eq!(ql.n_nonpositive, 0);
    assert_eq!(q1.n_nonpositive, 0);
    assert!(q1.min_scaled_jacobian >= 0.3 - 1e-12 && q1.min_scaled_jacobian < 1.0);
    assert!((q0.min_scaled_jacobian - 1.0).abs() < 1e-12);
    assert!(q1.smoothing.movable_nodes > 0);
    // every corner of every element positive
    for c in &sm.elements {
        let j = jacobian::corner_jacobians(&jacobian::element_coords(&sm.nodes, c));
        assert!(j.iter().all(|&x| x > 0.0));
    }
}

#[test]
fn aggressive_smoothing_still_never_inverts() {
    let v = sphere(15, 1e-3, 5.6e-3);
    let opts = MeshOptions {
        smoothing: SmoothOptions {
            iterations: 60,
            lambda: 0.9,
            mu: -0.95,
            min_scaled_jacobian: 0.05,
            min_length_ratio: 0.05,
            interfaces: true,
        },
        ..Default::default()
    };
    let (_, q) = mesh_volume(&v, &map12(), &opts).unwrap();
    assert_eq!(q.n_nonpositive, 0);
    assert!(q.min_scaled_jacobian > 0.0);
}

#[test]
fn smoothing_is_deterministic_across_thread_counts() {
    let v = sphere(15, 1e-3, 5.6e-3);
    let run = |t| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
            .install(|| {
                mesh_volume(&v, &map12(), &MeshOptions::default())
                    .unwrap()
                    .0
            })
    };
    let (a, b) = (run(1), run(3));
    assert_eq!(a.nodes, b.nodes);
}

#[test]
fn cut_planes_stay_planar() {
    // a half sphere cut by the volume's k = 0 face
    let v0 = sphere(21, 1e-3, 8.4e-3);
    let v = v0.crop([0, 0, 10], [21, 21, 21]);
    let (m, q) = mesh_volume(&v, &map12(), &MeshOptions::default()).unwrap();
    assert_eq!(q.n_nonpositive, 0);
    let zmin = v.index_to_world([0.0, 0.0, -0.5])[2];
    let on = m.nodes_on_plane(2, zmin, 1e-12);
    let faces_on_plane = m
        .boundary_faces()
        .iter()
        .filter(|f| {
            f.nodes
                .iter()
                .all(|&n| (m.nodes[n as usize][2] - zmin).abs() < 1e-12)
        })
        .count();
    assert!(on.len() > 50 && faces_on_plane > 40);
}

#[test]
fn coarsening_merges_blocks_by_majority() {
    let v = sphere(20, 1e-3, 8e-3);
    let c = v.coarsen(2);
    assert_eq!(c.dims, [10, 10, 10]);
    assert_eq!(c.spacing, [2e-3; 3]);
    // the merged voxel centre is the centre of its block
    let a = c.voxel_center(0, 0, 0);
    let b = v.index_to_world([0.5, 0.5, 0.5]);
    assert!((0..3).all(|k| (a[k] - b[k]).abs() < 1e-15));
    let (m, _) = mesh_volume(
        &v,
        &map12(),
        &MeshOptions {
            coarsen: 2,
            ..no_smooth()
        },
    )
    .unwrap();
    let n1 = v.label_counts()[1..].iter().sum::<usize>() as f64;
    assert!((m.n_elements() as f64 * 8.0 - n1).abs() < 0.2 * n1);
}

#[test]
fn nifti_round_trip_gives_the_same_mesh() {
    let dir = std::env::temp_dir().join(format!("palpa-nifti-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut v = sphere(13, 1.5e-3, 5e-3);
    // non-trivial origin
    v.affine[0][3] += 0.0125;
    v.affine[1][3] -= 0.25;
    for name in ["labels.nii", "labels.nii.gz"] {
        let p = dir.join(name);
        write_nifti(&v, &p).unwrap();
        let r = read_nifti(&p).unwrap();
        assert_eq!(r.dims, v.dims);
        assert_eq!(r.labels, v.labels);
        for a in 0..3 {
            assert!((r.spacing[a] - v.spacing[a]).abs() < 1e-9);
            for b in 0..4 {
                assert!(
                    (r.affine[a][b] - v.affine[a][b]).abs() < 1e-9,
                    "{name} affine"
                );
            }
        }
        let (m0, _) = mesh_volume(&v, &map12(), &MeshOptions::default()).unwrap();
        let (m1, _) = mesh_volume(&r, &map12(), &MeshOptions::default()).unwrap();
        assert_eq!(m0.elements, m1.elements);
        assert_eq!(m0.element_part, m1.element_part);
        let dmax = m0
            .nodes
            .iter()
            .zip(&m1.nodes)
            .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).abs()).fold(0.0, f64::max))
            .fold(0.0, f64::max);
        assert!(dmax < 1e-9, "{name}: nodes differ by {dmax}");
    }
    let j = dir.join("labels.json");
    write_raw(&v, &j).unwrap();
    assert_eq!(read_volume(&j).unwrap(), v);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn mirrored_affine_still_gives_positive_jacobians() {
    let mut v = sphere(9, 1e-3, 3.5e-3);
    v.affine[0][0] = -1e-3;
    let (_, q) = mesh_volume(&v, &map12(), &MeshOptions::default()).unwrap();
    assert_eq!(q.n_nonpositive, 0);
    assert!(q.min_scaled_jacobian > 0.0);
}

#[test]
fn label_map_parses_toml() {
    let m =
        LabelMap::from_toml_str("[labels]\n1 = \"flesh\"\n2 = \"liver\"\n7 = \"flesh\"\n").unwrap();
    let (names, table) = m.parts();
    assert_eq!(names, vec!["flesh".to_string(), "liver".to_string()]);
    assert_eq!(table[7], 0);
    assert_eq!(table[2], 1);
    assert!(LabelMap::from_toml_str("0 = \"bg\"").is_err());
}

#[test]
fn preview_writes_three_pngs() {
    let dir = std::env::temp_dir().join(format!("palpa-preview-{}", std::process::id()));
    let v = sphere(11, 1e-3, 4e-3);
    let files = write_preview(&v, &dir).unwrap();
    assert_eq!(files.len(), 3);
    for f in &files {
        let b = std::fs::read(f).unwrap();
        assert_eq!(&b[1..4], b"PNG");
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Found by the nifti fuzz target (docs/fuzzing.md): a header whose `datatype` disagrees with
/// its `bitpix` (here int64 with 8 bits, and uint8 with 0) made the nifti crate panic while
/// decoding the voxels ("Inconsistent raw data size").
#[test]
fn a_nifti_whose_bitpix_disagrees_with_its_datatype_is_an_error_not_a_panic() {
    let dir = std::env::temp_dir().join(format!("palpa-nifti-bitpix-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let v = LabelVolume::new([4, 3, 2], [1e-3; 3], [0.0; 3]);
    let good = dir.join("good.nii");
    write_nifti(&v, &good).unwrap();
    let bytes = std::fs::read(&good).unwrap();
    // datatype at byte 70, bitpix at byte 72 (little-endian i16)
    for (datatype, bitpix, name) in [(1024i16, 8i16, "int64"), (2, 0, "uint8")] {
        let mut b = bytes.clone();
        b[70..72].copy_from_slice(&datatype.to_le_bytes());
        b[72..74].copy_from_slice(&bitpix.to_le_bytes());
        let p = dir.join(format!("bad-{name}.nii"));
        std::fs::write(&p, &b).unwrap();
        let e = read_nifti(&p).unwrap_err();
        assert!(
            e.contains(&format!("bitpix ({bitpix}) does not match its datatype")),
            "{name}: {e}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Found by the raw_volume fuzz target (docs/fuzzing.md): a JSON header whose dims multiply
/// past `usize` (`[2, 1e19, 1]`) overflowed in `LabelVolume::from_affine` (a panic in debug
/// builds; in release the wrapped product could match the data and pass absurd dims on). The
/// header is checked first, and the data file's size against the dims before it is read.
#[test]
fn a_raw_volume_whose_dims_overflow_is_an_error_not_a_panic() {
    let dir = std::env::temp_dir().join(format!("palpa-raw-dims-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let j = dir.join("labels.json");
    write_raw(&LabelVolume::new([2, 1, 1], [1e-3; 3], [0.0; 3]), &j).unwrap();
    let good = std::fs::read_to_string(&j).unwrap();
    let header = |dims: &str| {
        let v: serde_json::Value = serde_json::from_str(&good).unwrap();
        let mut v = v.as_object().unwrap().clone();
        v.insert("dims".into(), serde_json::from_str(dims).unwrap());
        std::fs::write(&j, serde_json::to_string(&v).unwrap()).unwrap();
        read_volume(&j).unwrap_err()
    };
    let e = header("[2, 10000000000000000000, 1]");
    assert!(
        e.contains("labels.json: dims") && e.contains("overflow"),
        "{e}"
    );
    let e = header("[2, 0, 1]");
    assert!(e.contains("at least one voxel along each axis"), "{e}");
    let e = header("[2, 2, 1]");
    assert!(
        e.contains("labels.raw: 2 bytes, but the dims [2, 2, 1] of") && e.contains("need 4"),
        "{e}"
    );
    // and the library call itself
    let e = LabelVolume::from_affine([usize::MAX, 2, 1], [[1.0; 4]; 4], vec![0; 2]).unwrap_err();
    assert!(e.contains("overflows"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}
