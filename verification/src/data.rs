//! The committed reference files (`verification/data/*.json`), embedded at compile time so the
//! `palpa` binary carries them, and small helpers to read them.
//!
//! Conventions (see `verification/python/README.md`): SI units, hex8 cells in VTK_HEXAHEDRON
//! order, displacement arrays `[node][x, y, z]` in input node order.

use serde_json::Value;
use solver::mesh::Mesh;

/// scikit-fem patch test.
pub const PATCH_SKFEM: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/data/patch_skfem.json"
));
/// FEniCSx patch test.
pub const PATCH_FENICSX: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/data/patch_fenicsx.json"
));
/// FEniCSx clamped neo-Hookean block.
pub const BLOCK_FENICSX: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/data/block_fenicsx.json"
));
/// scikit-fem cantilever.
pub const CANTILEVER_SKFEM: &str = include_str!(concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/data/cantilever_skfem.json"
));

/// Parse one of the embedded files.
pub fn parse(text: &str) -> Value {
    serde_json::from_str(text).expect("committed reference JSON is valid")
}

/// Walk a path of keys (objects) and indices (arrays, given as numbers in strings).
pub fn at<'a>(v: &'a Value, path: &str) -> &'a Value {
    let mut cur = v;
    for k in path.split('.') {
        cur = match k.parse::<usize>() {
            Ok(i) => &cur[i],
            Err(_) => &cur[k],
        };
        if cur.is_null() {
            panic!("reference file has no `{path}` (missing `{k}`)");
        }
    }
    cur
}

/// A number.
pub fn f(v: &Value, path: &str) -> f64 {
    at(v, path)
        .as_f64()
        .unwrap_or_else(|| panic!("`{path}` is not a number"))
}

/// A string.
pub fn s<'a>(v: &'a Value, path: &str) -> &'a str {
    at(v, path)
        .as_str()
        .unwrap_or_else(|| panic!("`{path}` is not a string"))
}

/// An array of node ids.
pub fn vec_u32(v: &Value, path: &str) -> Vec<u32> {
    at(v, path)
        .as_array()
        .unwrap_or_else(|| panic!("`{path}` is not an array"))
        .iter()
        .map(|x| x.as_u64().unwrap() as u32)
        .collect()
}

/// An array of 3-vectors.
pub fn vec3(v: &Value, path: &str) -> Vec<[f64; 3]> {
    at(v, path)
        .as_array()
        .unwrap_or_else(|| panic!("`{path}` is not an array"))
        .iter()
        .map(|r| {
            let r = r.as_array().unwrap();
            [
                r[0].as_f64().unwrap(),
                r[1].as_f64().unwrap(),
                r[2].as_f64().unwrap(),
            ]
        })
        .collect()
}

/// The mesh stored under `path` (`nodes`, `cells`), as a one-part palpa mesh.
pub fn mesh(v: &Value, path: &str, part: &str) -> Mesh {
    let m = at(v, path);
    let nodes = vec3(m, "nodes");
    let elements: Vec<[u32; 8]> = at(m, "cells")
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            let c = c.as_array().unwrap();
            std::array::from_fn(|a| c[a].as_u64().unwrap() as u32)
        })
        .collect();
    Mesh {
        element_part: vec![0; elements.len()],
        nodes,
        elements,
        part_names: vec![part.to_string()],
        ..Default::default()
    }
}
