//! Abaqus input files (`.inp`): the mesh part of a flat input file or of one `*Part` (with at
//! most one `*Instance` of it, without translation or rotation). Nodes that Abaqus/CAE writes at
//! the assembly level (reference points, outside any `*Instance`) and node sets over them are
//! skipped with a note: their labels restart at 1 and would collide with the part's.
//!
//! Hand-written: no maintained Rust crate reads Abaqus input. The syntax (Abaqus Keywords
//! Reference): keyword lines `*Keyword, param=value, flag` (case-insensitive), data lines of
//! comma-separated values (a line ending in a comma continues on the next), `**` comments,
//! `*Include, input=FILE`. Read here:
//!
//! | keyword | what palpa takes |
//! |---|---|
//! | `*Node` | node label, x, y, z |
//! | `*Element, type=C3D8...` (C3D8, C3D8R, C3D8H, C3D8I, ...) | hexahedra (C3D8 node order is VTK's); `elset=` puts them in a set |
//! | `*Element` of other types | other volume elements (C3D4, C3D6, C3D10, C3D20, ...) are refused; shells, membranes, rigid and 2-D elements are counted and left out |
//! | `*Nset`, `*Elset` (`generate`, set names as members) | node and element sets |
//! | `*Solid Section, elset=E` | the parts: one per section, named by its element set |
//!
//! Without `*Solid Section` the parts are the `elset=` of the `*Element` blocks, else one part
//! `body`. Everything else (materials, steps, boundary conditions) is skipped: the scene states
//! the physics.

use super::RawMesh;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

struct Line {
    file: PathBuf,
    no: usize,
    text: String,
}

/// Read a `.inp` file.
pub fn read(path: &Path) -> Result<RawMesh, String> {
    let mut lines = Vec::new();
    load(path, &mut lines, 0)?;
    parse(&lines)
}

fn load(path: &Path, out: &mut Vec<Line>, depth: usize) -> Result<(), String> {
    if depth > 16 {
        return Err(format!("{}: *Include nested too deep", path.display()));
    }
    let src = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    for (i, l) in src.lines().enumerate() {
        let t = l.trim();
        if t.is_empty() || t.starts_with("**") {
            continue;
        }
        if let Some(kw) = t.strip_prefix('*') {
            let (name, params) = keyword(kw);
            if name == "include" {
                let f = params.get("input").ok_or_else(|| {
                    format!("{}:{}: *Include without input=", path.display(), i + 1)
                })?;
                let inc = path
                    .parent()
                    .unwrap_or(Path::new("."))
                    .join(f.trim_matches('"'));
                load(&inc, out, depth + 1)?;
                continue;
            }
        }
        out.push(Line {
            file: path.to_path_buf(),
            no: i + 1,
            text: t.to_string(),
        });
    }
    Ok(())
}

/// `Keyword, a=b, c` -> ("keyword", {a: b, c: ""}), lower-case names.
fn keyword(s: &str) -> (String, BTreeMap<String, String>) {
    let mut it = s.split(',');
    let name = it.next().unwrap_or("").trim().to_ascii_lowercase();
    let name = name.split_whitespace().collect::<Vec<_>>().join(" ");
    let params = it
        .map(|p| {
            let mut kv = p.splitn(2, '=');
            let k = kv.next().unwrap_or("").trim().to_ascii_lowercase();
            let v = kv.next().unwrap_or("").trim().to_string();
            (k, v)
        })
        .filter(|(k, _)| !k.is_empty())
        .collect();
    (name, params)
}

/// A set's members as the file lists them: labels, and `generate` ranges (first, last,
/// increment) kept as ranges until the labels are known. Both without repeats, so a set
/// listing another set (or itself) again and again does not grow, and a range over labels the
/// file does not define costs nothing.
#[derive(Clone, Default)]
struct Members {
    labels: BTreeSet<i64>,
    ranges: BTreeSet<(i64, i64, i64)>,
}

impl Members {
    fn add(&mut self, other: &Members) {
        self.labels.extend(&other.labels);
        self.ranges.extend(&other.ranges);
    }

    /// The members' indices by `index` (label -> index). `strict`: a label `index` lacks is the
    /// error (`Err(label)`); otherwise it is left out. Each range is walked label by label only
    /// while its labels are defined (strict), or over the defined labels it spans.
    fn resolve(&self, index: &BTreeMap<i64, u32>, strict: bool) -> Result<Vec<u32>, i64> {
        let mut out = Vec::new();
        for id in &self.labels {
            match index.get(id) {
                Some(&i) => out.push(i),
                None if strict => return Err(*id),
                None => {}
            }
        }
        for &(a, b, s) in &self.ranges {
            if strict {
                let mut id = a;
                loop {
                    out.push(*index.get(&id).ok_or(id)?);
                    match id.checked_add(s) {
                        Some(next) if next <= b => id = next,
                        _ => break,
                    }
                }
            } else {
                out.extend(
                    index
                        .range(a..=b)
                        .filter(|(&l, _)| (l as i128 - a as i128) % s as i128 == 0)
                        .map(|(_, &i)| i),
                );
            }
        }
        Ok(out)
    }
}

fn parse(lines: &[Line]) -> Result<RawMesh, String> {
    let at = |l: &Line| format!("{}:{}", l.file.display(), l.no);
    let mut raw = RawMesh::default();
    let mut node_index: BTreeMap<i64, u32> = BTreeMap::new();
    // The *Element elset of each hexahedron.
    let mut hex_elset: Vec<Option<String>> = Vec::new();
    let mut elem_index: BTreeMap<i64, u32> = BTreeMap::new();
    // The label of each hexahedron.
    let mut hex_ids: Vec<i64> = Vec::new();
    let mut nsets: BTreeMap<String, Members> = BTreeMap::new();
    let mut elsets: BTreeMap<String, Members> = BTreeMap::new();
    let mut sections: Vec<(String, String)> = Vec::new(); // (elset, where)
    let mut parts_seen = 0;
    let mut instances = 0;
    // Inside *Assembly ... *End Assembly, and inside *Instance ... *End Instance.
    let (mut in_assembly, mut in_instance) = (false, false);
    let mut skipped_nodes = 0usize;
    let mut skipped_sets: Vec<String> = Vec::new();
    // Where each node set was (first) defined, for messages.
    let mut nset_at: BTreeMap<String, String> = BTreeMap::new();
    let mut i = 0;
    while i < lines.len() {
        let l = &lines[i];
        let Some(kw) = l.text.strip_prefix('*') else {
            return Err(format!(
                "{}: data line `{}` outside a keyword that takes data",
                at(l),
                l.text
            ));
        };
        let (name, params) = keyword(kw);
        // The data lines of this keyword, joined where a line ends in a comma.
        let mut data: Vec<(&Line, Vec<String>)> = Vec::new();
        i += 1;
        while i < lines.len() && !lines[i].text.starts_with('*') {
            let first = &lines[i];
            let mut text = first.text.clone();
            while text.trim_end().ends_with(',')
                && i + 1 < lines.len()
                && !lines[i + 1].text.starts_with('*')
            {
                i += 1;
                text.push_str(&lines[i].text);
            }
            let fields = text
                .split(',')
                .map(|s| s.trim().to_string())
                .filter(|s| !s.is_empty())
                .collect();
            data.push((first, fields));
            i += 1;
        }
        let num = |d: &(&Line, Vec<String>), k: usize, what: &str| -> Result<f64, String> {
            let s =
                d.1.get(k)
                    .ok_or_else(|| format!("{}: {what} missing", at(d.0)))?;
            s.parse::<f64>()
                .map_err(|_| format!("{}: {what} `{s}` is not a number", at(d.0)))
        };
        let label = |d: &(&Line, Vec<String>), k: usize, what: &str| -> Result<i64, String> {
            let s =
                d.1.get(k)
                    .ok_or_else(|| format!("{}: {what} missing", at(d.0)))?;
            s.parse::<i64>()
                .map_err(|_| format!("{}: {what} `{s}` is not an integer label", at(d.0)))
        };
        match name.as_str() {
            "part" => {
                parts_seen += 1;
                if parts_seen > 1 {
                    return Err(format!(
                        "{}: a second *Part; palpa reads one part (or a flat input file without parts)",
                        at(l)
                    ));
                }
            }
            "assembly" => in_assembly = true,
            "end assembly" => in_assembly = false,
            "end instance" => in_instance = false,
            "node" if in_assembly && !in_instance => skipped_nodes += data.len(),
            "nset" if in_assembly && !in_instance && !params.contains_key("instance") => {
                if let Some(n) = params.get("nset") {
                    skipped_sets.push(n.clone());
                }
            }
            "instance" => {
                in_instance = true;
                instances += 1;
                if instances > 1 {
                    return Err(format!(
                        "{}: a second *Instance; palpa reads one instance of one part",
                        at(l)
                    ));
                }
                if !data.is_empty() {
                    return Err(format!(
                        "{}: *Instance with a translation or rotation; palpa reads the part where it is \
                         (apply the transformation to the part's nodes, or write a flat input file)",
                        at(l)
                    ));
                }
            }
            "node" => {
                for d in &data {
                    let id = label(d, 0, "node label")?;
                    if d.1.len() < 4 {
                        return Err(format!(
                            "{}: node {id} has no z coordinate; palpa reads 3-D meshes",
                            at(d.0)
                        ));
                    }
                    let x = [num(d, 1, "x")?, num(d, 2, "y")?, num(d, 3, "z")?];
                    if node_index.insert(id, raw.nodes.len() as u32).is_some() {
                        return Err(format!("{}: node {id} is defined twice", at(d.0)));
                    }
                    raw.nodes.push(x);
                    raw.node_ids.push(id);
                }
                if let Some(s) = params.get("nset") {
                    nset_at.entry(s.to_string()).or_insert_with(|| at(l));
                    let ids = data.iter().filter_map(|d| d.1[0].parse::<i64>().ok());
                    nsets.entry(s.to_string()).or_default().labels.extend(ids);
                }
            }
            "element" => {
                let ty = params
                    .get("type")
                    .ok_or_else(|| format!("{}: *Element without type=", at(l)))?
                    .to_ascii_uppercase();
                let hex = ty.starts_with("C3D8");
                let volume = ty.starts_with("C3D") || ty.starts_with("DC3D");
                let elset = params.get("elset").cloned();
                for d in &data {
                    let id = label(d, 0, "element label")?;
                    if hex {
                        if d.1.len() != 9 {
                            return Err(format!(
                                "{}: {ty} element {id} has {} nodes; C3D8 elements have 8",
                                at(d.0),
                                d.1.len() - 1
                            ));
                        }
                        let mut h = [0u32; 8];
                        for (k, slot) in h.iter_mut().enumerate() {
                            let n = label(d, k + 1, "node label")?;
                            *slot = *node_index.get(&n).ok_or_else(|| {
                                format!(
                                    "{}: element {id} refers to node {n}, which no *Node above defines",
                                    at(d.0)
                                )
                            })?;
                        }
                        if elem_index.insert(id, raw.hexes.len() as u32).is_some() {
                            return Err(format!("{}: element {id} is defined twice", at(d.0)));
                        }
                        raw.hexes.push(h);
                        hex_ids.push(id);
                        raw.hex_labels.push(format!(
                            "element {id} ({}:{})",
                            d.0.file.display(),
                            d.0.no
                        ));
                        hex_elset.push(elset.clone());
                    } else if volume {
                        *raw.other_volume
                            .entry(format!("{ty} elements"))
                            .or_default() += 1;
                    } else {
                        *raw.other_lower.entry(format!("{ty} elements")).or_default() += 1;
                    }
                }
                if let (Some(s), true) = (&elset, hex) {
                    let ids = data.iter().filter_map(|d| d.1[0].parse::<i64>().ok());
                    elsets.entry(s.clone()).or_default().labels.extend(ids);
                }
            }
            "nset" | "elset" => {
                let key = if name == "nset" { "nset" } else { "elset" };
                let set = params
                    .get(key)
                    .ok_or_else(|| {
                        format!(
                            "{}: *{} without {key}=",
                            at(l),
                            kw.split(',').next().unwrap_or("")
                        )
                    })?
                    .clone();
                let generate = params.contains_key("generate");
                let mut members = Members::default();
                // the sets this keyword lists, each merged once
                let mut listed: BTreeSet<&str> = BTreeSet::new();
                for d in &data {
                    if generate {
                        let a = label(d, 0, "first label")?;
                        let b = label(d, 1, "last label")?;
                        let s = if d.1.len() > 2 {
                            label(d, 2, "increment")?
                        } else {
                            1
                        };
                        if s <= 0 || b < a {
                            return Err(format!(
                                "{}: generate `{a}, {b}, {s}` is empty or runs backwards",
                                at(d.0)
                            ));
                        }
                        members.ranges.insert((a, b, s));
                    } else {
                        for tok in &d.1 {
                            match tok.parse::<i64>() {
                                Ok(v) => {
                                    members.labels.insert(v);
                                }
                                Err(_) => {
                                    if !listed.insert(tok.as_str()) {
                                        continue;
                                    }
                                    let sets = if key == "nset" { &nsets } else { &elsets };
                                    let other = sets.iter().find(|(k, _)| k.eq_ignore_ascii_case(tok)).map(|(_, v)| v).ok_or_else(|| {
                                        format!("{}: `{tok}` is neither a label nor a set defined above", at(d.0))
                                    })?;
                                    members.add(other);
                                }
                            }
                        }
                    }
                }
                let sets = if key == "nset" {
                    nset_at.entry(set.clone()).or_insert_with(|| at(l));
                    &mut nsets
                } else {
                    &mut elsets
                };
                sets.entry(set).or_default().add(&members);
            }
            "solid section" => {
                let e = params
                    .get("elset")
                    .ok_or_else(|| format!("{}: *Solid Section without elset=", at(l)))?;
                sections.push((e.clone(), at(l)));
            }
            _ => {}
        }
    }
    if skipped_nodes > 0 {
        raw.notes.push(format!(
            "{skipped_nodes} node(s) at the assembly level (reference points) skipped{}",
            if skipped_sets.is_empty() {
                String::new()
            } else {
                format!(", with the node set(s) {}", skipped_sets.join(", "))
            }
        ));
    }
    // Sets: labels -> indices; element sets keep hexahedra only.
    for (name, m) in &nsets {
        let v = m.resolve(&node_index, true).map_err(|id| {
            let at = nset_at
                .get(name)
                .map_or(String::new(), |w| format!("{w}: "));
            format!("{at}node set `{name}` lists node {id}, which no *Node defines")
        })?;
        raw.node_sets.insert(name.clone(), v);
    }
    let mut hex_sets: BTreeMap<&str, Vec<u32>> = BTreeMap::new();
    for (name, m) in &elsets {
        let v = m.resolve(&elem_index, false).unwrap_or_default();
        if !v.is_empty() {
            raw.element_sets.insert(name.clone(), v.clone());
        }
        hex_sets.insert(name, v);
    }
    // Parts.
    let mut part_of: Vec<Option<usize>> = vec![None; raw.hexes.len()];
    let mut names: Vec<String> = Vec::new();
    if !sections.is_empty() {
        for (elset, where_) in &sections {
            let hexes = hex_sets
                .iter()
                .find(|(k, _)| k.eq_ignore_ascii_case(elset))
                .map(|(_, v)| v)
                .ok_or_else(|| {
                    format!("{where_}: *Solid Section refers to element set `{elset}`, which is not defined")
                })?;
            let key = names.len();
            names.push(elset.clone());
            for &e in hexes {
                if let Some(prev) = part_of[e as usize] {
                    if prev == key {
                        continue;
                    }
                    return Err(format!(
                        "{where_}: element {} is in two solid sections (`{}` and `{elset}`)",
                        hex_ids[e as usize], names[prev]
                    ));
                }
                part_of[e as usize] = Some(key);
            }
        }
    }
    let mut key_of_name: BTreeMap<String, usize> = names
        .iter()
        .enumerate()
        .map(|(k, n)| (n.clone(), k))
        .collect();
    let mut hex_part = Vec::with_capacity(raw.hexes.len());
    for (e, p) in part_of.iter().enumerate() {
        let k = match p {
            Some(k) => *k,
            None => {
                let n = hex_elset[e].clone().unwrap_or_else(|| "body".to_string());
                *key_of_name.entry(n.clone()).or_insert_with(|| {
                    names.push(n);
                    names.len() - 1
                })
            }
        };
        hex_part.push(k as i64);
    }
    raw.part_names = names
        .into_iter()
        .enumerate()
        .map(|(k, n)| (k as i64, n))
        .collect();
    raw.hex_part = Some(hex_part);
    Ok(raw)
}
