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

/// `file:line` of a line, for messages.
fn at(l: &Line) -> String {
    format!("{}:{}", l.file.display(), l.no)
}

/// One data line of a keyword (continuation lines joined): the line it starts on and its
/// comma-separated fields, empty fields left out.
struct DataLine<'a> {
    line: &'a Line,
    fields: Vec<String>,
}

impl DataLine<'_> {
    /// Field `k` as a number; `what` names it in the error.
    fn num(&self, k: usize, what: &str) -> Result<f64, String> {
        let s = self
            .fields
            .get(k)
            .ok_or_else(|| format!("{}: {what} missing", at(self.line)))?;
        s.parse::<f64>()
            .map_err(|_| format!("{}: {what} `{s}` is not a number", at(self.line)))
    }

    /// Field `k` as an integer label; `what` names it in the error.
    fn label(&self, k: usize, what: &str) -> Result<i64, String> {
        let s = self
            .fields
            .get(k)
            .ok_or_else(|| format!("{}: {what} missing", at(self.line)))?;
        s.parse::<i64>()
            .map_err(|_| format!("{}: {what} `{s}` is not an integer label", at(self.line)))
    }
}

/// The data lines from line `i` up to the next keyword line, joined where a line ends in a
/// comma, and the index of that keyword line.
fn data_lines(lines: &[Line], mut i: usize) -> (Vec<DataLine<'_>>, usize) {
    let mut data = Vec::new();
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
        data.push(DataLine {
            line: first,
            fields,
        });
        i += 1;
    }
    (data, i)
}

/// The labels in the first field of each data line (those that are integers).
fn first_labels<'a>(data: &'a [DataLine]) -> impl Iterator<Item = i64> + 'a {
    data.iter().filter_map(|d| d.fields[0].parse::<i64>().ok())
}

/// One keyword line and its data lines.
struct Keyword<'a> {
    /// The keyword line.
    line: &'a Line,
    /// Its text after the `*`.
    text: &'a str,
    /// Its lower-case name.
    name: String,
    /// Its parameters (lower-case names).
    params: BTreeMap<String, String>,
    data: Vec<DataLine<'a>>,
}

/// What the parser has read so far, keyword by keyword.
#[derive(Default)]
struct Parser {
    raw: RawMesh,
    node_index: BTreeMap<i64, u32>,
    /// The *Element elset of each hexahedron.
    hex_elset: Vec<Option<String>>,
    elem_index: BTreeMap<i64, u32>,
    /// The label of each hexahedron.
    hex_ids: Vec<i64>,
    nsets: BTreeMap<String, Members>,
    elsets: BTreeMap<String, Members>,
    /// `*Solid Section`s: (elset, where).
    sections: Vec<(String, String)>,
    parts_seen: usize,
    instances: usize,
    /// Inside *Assembly ... *End Assembly.
    in_assembly: bool,
    /// Inside *Instance ... *End Instance.
    in_instance: bool,
    skipped_nodes: usize,
    skipped_sets: Vec<String>,
    /// Where each node set was (first) defined, for messages.
    nset_at: BTreeMap<String, String>,
}

/// The mesh that the lines of an input file (includes read in) state, keyword by keyword.
fn parse(lines: &[Line]) -> Result<RawMesh, String> {
    let mut p = Parser::default();
    let mut i = 0;
    while i < lines.len() {
        let l = &lines[i];
        let Some(text) = l.text.strip_prefix('*') else {
            return Err(format!(
                "{}: data line `{}` outside a keyword that takes data",
                at(l),
                l.text
            ));
        };
        let (name, params) = keyword(text);
        let (data, next) = data_lines(lines, i + 1);
        i = next;
        p.keyword(&Keyword {
            line: l,
            text,
            name,
            params,
            data,
        })?;
    }
    p.finish()
}

impl Parser {
    /// Take one keyword: structure (`*Part`, `*Assembly`, `*Instance`), nodes, elements, sets
    /// and sections; anything else is skipped.
    fn keyword(&mut self, k: &Keyword) -> Result<(), String> {
        let assembly_level = self.in_assembly && !self.in_instance;
        match k.name.as_str() {
            "part" => {
                self.parts_seen += 1;
                if self.parts_seen > 1 {
                    return Err(format!(
                        "{}: a second *Part; palpa reads one part (or a flat input file without parts)",
                        at(k.line)
                    ));
                }
            }
            "assembly" => self.in_assembly = true,
            "end assembly" => self.in_assembly = false,
            "end instance" => self.in_instance = false,
            "node" if assembly_level => self.skipped_nodes += k.data.len(),
            "nset" if assembly_level && !k.params.contains_key("instance") => {
                if let Some(n) = k.params.get("nset") {
                    self.skipped_sets.push(n.clone());
                }
            }
            "instance" => self.instance(k)?,
            "node" => self.nodes(k)?,
            "element" => self.elements(k)?,
            "nset" | "elset" => self.set(k)?,
            "solid section" => {
                let e = k
                    .params
                    .get("elset")
                    .ok_or_else(|| format!("{}: *Solid Section without elset=", at(k.line)))?;
                self.sections.push((e.clone(), at(k.line)));
            }
            _ => {}
        }
        Ok(())
    }

    /// `*Instance`: one, without a translation or rotation.
    fn instance(&mut self, k: &Keyword) -> Result<(), String> {
        self.in_instance = true;
        self.instances += 1;
        if self.instances > 1 {
            return Err(format!(
                "{}: a second *Instance; palpa reads one instance of one part",
                at(k.line)
            ));
        }
        if !k.data.is_empty() {
            return Err(format!(
                "{}: *Instance with a translation or rotation; palpa reads the part where it is \
                 (apply the transformation to the part's nodes, or write a flat input file)",
                at(k.line)
            ));
        }
        Ok(())
    }

    /// `*Node`: label, x, y, z per line; `nset=` adds the nodes to a set.
    fn nodes(&mut self, k: &Keyword) -> Result<(), String> {
        for d in &k.data {
            let id = d.label(0, "node label")?;
            if d.fields.len() < 4 {
                return Err(format!(
                    "{}: node {id} has no z coordinate; palpa reads 3-D meshes",
                    at(d.line)
                ));
            }
            let x = [d.num(1, "x")?, d.num(2, "y")?, d.num(3, "z")?];
            if self
                .node_index
                .insert(id, self.raw.nodes.len() as u32)
                .is_some()
            {
                return Err(format!("{}: node {id} is defined twice", at(d.line)));
            }
            self.raw.nodes.push(x);
            self.raw.node_ids.push(id);
        }
        if let Some(s) = k.params.get("nset") {
            self.nset_at
                .entry(s.to_string())
                .or_insert_with(|| at(k.line));
            let ids = first_labels(&k.data);
            self.nsets
                .entry(s.to_string())
                .or_default()
                .labels
                .extend(ids);
        }
        Ok(())
    }

    /// `*Element`: hexahedra (C3D8...) are read, other volume elements and lower-dimensional
    /// ones counted; `elset=` puts the hexahedra in a set.
    fn elements(&mut self, k: &Keyword) -> Result<(), String> {
        let ty = k
            .params
            .get("type")
            .ok_or_else(|| format!("{}: *Element without type=", at(k.line)))?
            .to_ascii_uppercase();
        let hex = ty.starts_with("C3D8");
        let volume = ty.starts_with("C3D") || ty.starts_with("DC3D");
        let elset = k.params.get("elset").cloned();
        for d in &k.data {
            let id = d.label(0, "element label")?;
            if hex {
                self.hex(d, id, &ty, &elset)?;
            } else if volume {
                *self
                    .raw
                    .other_volume
                    .entry(format!("{ty} elements"))
                    .or_default() += 1;
            } else {
                *self
                    .raw
                    .other_lower
                    .entry(format!("{ty} elements"))
                    .or_default() += 1;
            }
        }
        if let (Some(s), true) = (&elset, hex) {
            let ids = first_labels(&k.data);
            self.elsets.entry(s.clone()).or_default().labels.extend(ids);
        }
        Ok(())
    }

    /// One hexahedron (label `id`, type `ty`, in the `*Element`'s `elset`) from its data line.
    fn hex(
        &mut self,
        d: &DataLine,
        id: i64,
        ty: &str,
        elset: &Option<String>,
    ) -> Result<(), String> {
        if d.fields.len() != 9 {
            return Err(format!(
                "{}: {ty} element {id} has {} nodes; C3D8 elements have 8",
                at(d.line),
                d.fields.len() - 1
            ));
        }
        let mut h = [0u32; 8];
        for (k, slot) in h.iter_mut().enumerate() {
            let n = d.label(k + 1, "node label")?;
            *slot = *self.node_index.get(&n).ok_or_else(|| {
                format!(
                    "{}: element {id} refers to node {n}, which no *Node above defines",
                    at(d.line)
                )
            })?;
        }
        if self
            .elem_index
            .insert(id, self.raw.hexes.len() as u32)
            .is_some()
        {
            return Err(format!("{}: element {id} is defined twice", at(d.line)));
        }
        self.raw.hexes.push(h);
        self.hex_ids.push(id);
        self.raw.hex_labels.push(format!(
            "element {id} ({}:{})",
            d.line.file.display(),
            d.line.no
        ));
        self.hex_elset.push(elset.clone());
        Ok(())
    }

    /// `*Nset` or `*Elset`: labels, `generate` ranges or sets defined above, added to the set.
    fn set(&mut self, k: &Keyword) -> Result<(), String> {
        let key = if k.name == "nset" { "nset" } else { "elset" };
        let set = k
            .params
            .get(key)
            .ok_or_else(|| {
                format!(
                    "{}: *{} without {key}=",
                    at(k.line),
                    k.text.split(',').next().unwrap_or("")
                )
            })?
            .clone();
        let members = if k.params.contains_key("generate") {
            generated_members(&k.data)?
        } else {
            self.listed_members(key, &k.data)?
        };
        let sets = if key == "nset" {
            self.nset_at
                .entry(set.clone())
                .or_insert_with(|| at(k.line));
            &mut self.nsets
        } else {
            &mut self.elsets
        };
        sets.entry(set).or_default().add(&members);
        Ok(())
    }

    /// The members that a set's data lines list: labels, and the sets of kind `key` (`nset`
    /// or `elset`) defined above, each merged once.
    fn listed_members(&self, key: &str, data: &[DataLine]) -> Result<Members, String> {
        let mut members = Members::default();
        // the sets this keyword lists, each merged once
        let mut listed: BTreeSet<&str> = BTreeSet::new();
        for d in data {
            for tok in &d.fields {
                match tok.parse::<i64>() {
                    Ok(v) => {
                        members.labels.insert(v);
                    }
                    Err(_) => {
                        if !listed.insert(tok.as_str()) {
                            continue;
                        }
                        let sets = if key == "nset" {
                            &self.nsets
                        } else {
                            &self.elsets
                        };
                        let other = sets
                            .iter()
                            .find(|(k, _)| k.eq_ignore_ascii_case(tok))
                            .map(|(_, v)| v)
                            .ok_or_else(|| {
                                format!(
                                    "{}: `{tok}` is neither a label nor a set defined above",
                                    at(d.line)
                                )
                            })?;
                        members.add(other);
                    }
                }
            }
        }
        Ok(members)
    }

    /// The report's note on what was skipped at the assembly level.
    fn note_skipped(&mut self) {
        if self.skipped_nodes > 0 {
            self.raw.notes.push(format!(
                "{} node(s) at the assembly level (reference points) skipped{}",
                self.skipped_nodes,
                if self.skipped_sets.is_empty() {
                    String::new()
                } else {
                    format!(", with the node set(s) {}", self.skipped_sets.join(", "))
                }
            ));
        }
    }

    /// The mesh: notes, sets resolved to indices, and parts.
    fn finish(mut self) -> Result<RawMesh, String> {
        self.note_skipped();
        self.resolve_node_sets()?;
        let hex_sets = self.resolve_element_sets();
        let (part_of, names) = self.section_parts(&hex_sets)?;
        self.assign_parts(&part_of, names);
        Ok(self.raw)
    }

    /// Node sets: labels -> indices; a label no `*Node` defines is an error.
    fn resolve_node_sets(&mut self) -> Result<(), String> {
        for (name, m) in &self.nsets {
            let v = m.resolve(&self.node_index, true).map_err(|id| {
                let at = self
                    .nset_at
                    .get(name)
                    .map_or(String::new(), |w| format!("{w}: "));
                format!("{at}node set `{name}` lists node {id}, which no *Node defines")
            })?;
            self.raw.node_sets.insert(name.clone(), v);
        }
        Ok(())
    }

    /// Element sets: labels -> indices of hexahedra (other elements left out); the mesh keeps
    /// the sets that hold any. Returns every set's hexahedra by name.
    fn resolve_element_sets(&mut self) -> BTreeMap<String, Vec<u32>> {
        let mut hex_sets: BTreeMap<String, Vec<u32>> = BTreeMap::new();
        for (name, m) in &self.elsets {
            let v = m.resolve(&self.elem_index, false).unwrap_or_default();
            if !v.is_empty() {
                self.raw.element_sets.insert(name.clone(), v.clone());
            }
            hex_sets.insert(name.clone(), v);
        }
        hex_sets
    }

    /// The part of each hexahedron from the `*Solid Section`s (None where no section holds
    /// it), and the parts' names (the sections' element sets); an element in two sections is
    /// an error.
    fn section_parts(
        &self,
        hex_sets: &BTreeMap<String, Vec<u32>>,
    ) -> Result<(Vec<Option<usize>>, Vec<String>), String> {
        let mut part_of: Vec<Option<usize>> = vec![None; self.raw.hexes.len()];
        let mut names: Vec<String> = Vec::new();
        for (elset, where_) in &self.sections {
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
                        self.hex_ids[e as usize], names[prev]
                    ));
                }
                part_of[e as usize] = Some(key);
            }
        }
        Ok((part_of, names))
    }

    /// The mesh's parts: each hexahedron's section part, else the `elset=` of its `*Element`,
    /// else `body`.
    fn assign_parts(&mut self, part_of: &[Option<usize>], mut names: Vec<String>) {
        let mut key_of_name: BTreeMap<String, usize> = names
            .iter()
            .enumerate()
            .map(|(k, n)| (n.clone(), k))
            .collect();
        let mut hex_part = Vec::with_capacity(self.raw.hexes.len());
        for (e, p) in part_of.iter().enumerate() {
            let k = match p {
                Some(k) => *k,
                None => {
                    let n = self.hex_elset[e]
                        .clone()
                        .unwrap_or_else(|| "body".to_string());
                    *key_of_name.entry(n.clone()).or_insert_with(|| {
                        names.push(n);
                        names.len() - 1
                    })
                }
            };
            hex_part.push(k as i64);
        }
        self.raw.part_names = names
            .into_iter()
            .enumerate()
            .map(|(k, n)| (k as i64, n))
            .collect();
        self.raw.hex_part = Some(hex_part);
    }
}

/// The members of a `generate` set: one range (first, last, increment 1 unless given) per
/// data line; an empty or backward range is an error.
fn generated_members(data: &[DataLine]) -> Result<Members, String> {
    let mut members = Members::default();
    for d in data {
        let a = d.label(0, "first label")?;
        let b = d.label(1, "last label")?;
        let s = if d.fields.len() > 2 {
            d.label(2, "increment")?
        } else {
            1
        };
        if s <= 0 || b < a {
            return Err(format!(
                "{}: generate `{a}, {b}, {s}` is empty or runs backwards",
                at(d.line)
            ));
        }
        members.ranges.insert((a, b, s));
    }
    Ok(members)
}
