//! Label map: which voxel label becomes which mesh part.
//!
//! Several labels may map to one part. Parts are numbered in order of their first label
//! (ascending label value), so the numbering is deterministic. A TOML file lists
//! `label = "part"` pairs, either at top level or under a `[labels]` table:
//!
//! ```toml
//! [labels]
//! 1 = "flesh"
//! 2 = "liver"
//! 3 = "ribs"
//! ```

use std::collections::BTreeMap;

/// Maps voxel labels (1..=255) to part names.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LabelMap {
    /// Label -> part name.
    pub labels: BTreeMap<u8, String>,
}

impl LabelMap {
    /// An empty map.
    pub fn new() -> Self {
        Self::default()
    }

    /// Builder: map `label` to `part`.
    pub fn with(mut self, label: u8, part: &str) -> Self {
        self.labels.insert(label, part.to_string());
        self
    }

    /// A map naming every label present in `counts` (non-zero count, label > 0) `label_N`.
    pub fn identity(counts: &[usize; 256]) -> Self {
        let mut m = LabelMap::new();
        for (l, &c) in counts.iter().enumerate().skip(1) {
            if c > 0 {
                m.labels.insert(l as u8, format!("label_{l}"));
            }
        }
        m
    }

    /// Parse the TOML form described in the module docs.
    pub fn from_toml_str(s: &str) -> Result<Self, String> {
        let v: toml::Table = s.parse().map_err(|e| format!("label map: {e}"))?;
        let table = match v.get("labels") {
            Some(toml::Value::Table(t)) => t.clone(),
            Some(_) => return Err("label map: `labels` must be a table".into()),
            None => v,
        };
        let mut m = LabelMap::new();
        for (k, val) in table {
            let l: u8 = k
                .trim()
                .parse()
                .map_err(|_| format!("label map: key `{k}` is not a label in 1..=255"))?;
            if l == 0 {
                return Err("label map: label 0 is background and cannot be a part".into());
            }
            let name = val
                .as_str()
                .ok_or_else(|| format!("label map: value of `{k}` must be a part name string"))?;
            m.labels.insert(l, name.to_string());
        }
        if m.labels.is_empty() {
            return Err("label map: no labels".into());
        }
        Ok(m)
    }

    /// Read a TOML label map file.
    pub fn from_toml_file(path: &std::path::Path) -> Result<Self, String> {
        let s = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Self::from_toml_str(&s)
    }

    /// Part names in part-id order, and a 256-entry table label -> part id (`u32::MAX` for
    /// background and unmapped labels).
    pub fn parts(&self) -> (Vec<String>, [u32; 256]) {
        let mut names: Vec<String> = Vec::new();
        let mut table = [u32::MAX; 256];
        for (&l, name) in &self.labels {
            let id = match names.iter().position(|n| n == name) {
                Some(p) => p,
                None => {
                    names.push(name.clone());
                    names.len() - 1
                }
            };
            table[l as usize] = id as u32;
        }
        (names, table)
    }
}
