//! Node numbering for locality: reverse Cuthill-McKee, and a seeded shuffle to measure what
//! locality is worth.
//!
//! The element loop gathers each element's eight nodes and adds its forces back into them; its
//! chunks of [`crate::model::CHUNK`] elements are coloured so that no two chunks of a colour share
//! a node (`model::colour_chunks`). Both want the nodes of neighbouring elements to lie
//! near each other in memory: a mesh numbered without locality (as some mesh generators and
//! converters write it) touches a new cache line for nearly every node and gets many colours of
//! few chunks. Reverse Cuthill-McKee (Cuthill and McKee 1969; George 1971's reversal) numbers
//! the nodes breadth-first from a pseudo-peripheral node, neighbours by increasing degree, and
//! reverses the order: it bounds the bandwidth `max |a - b|` over the node pairs of an element.
//! The ordering itself is `sprs`'s ([`sprs::linalg::reverse_cuthill_mckee`]); this module builds
//! the node graph and applies the permutation to the mesh (coordinates, connectivity, node
//! sets). Elements keep their numbers (element sets, parts and outputs by element are
//! unchanged); node ids in the outputs (VTK point order, messages naming a node) are the new
//! ones. `palpa bench --numbering` measures the three numberings (docs/performance.md).

use crate::mesh::Mesh;

/// How a scene's nodes are numbered before the model is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Numbering {
    /// As the mesh file or generator gives them.
    AsGiven,
    /// Reverse Cuthill-McKee.
    Rcm,
    /// A seeded random permutation (a measurement of what locality is worth, not for use).
    Shuffled,
}

impl Numbering {
    /// Parse `as_given`, `rcm` or `shuffled`.
    pub fn parse(s: &str) -> Result<Numbering, String> {
        match s {
            "as_given" => Ok(Numbering::AsGiven),
            "rcm" => Ok(Numbering::Rcm),
            "shuffled" => Ok(Numbering::Shuffled),
            o => Err(format!(
                "unknown numbering {o:?}: expected \"as_given\", \"rcm\" (reverse Cuthill-McKee) \
                 or \"shuffled\" (a seeded random order, to measure what locality is worth)"
            )),
        }
    }
    /// The label [`Numbering::parse`] reads.
    pub fn label(self) -> &'static str {
        match self {
            Numbering::AsGiven => "as_given",
            Numbering::Rcm => "rcm",
            Numbering::Shuffled => "shuffled",
        }
    }
}

/// The largest `|a - b|` over the node pairs of one element.
pub fn bandwidth(mesh: &Mesh) -> u32 {
    mesh.elements
        .iter()
        .map(|e| e.iter().max().unwrap() - e.iter().min().unwrap())
        .max()
        .unwrap_or(0)
}

/// The reverse Cuthill-McKee order of the mesh's nodes: `order[new] = old`. Two nodes are
/// adjacent when they share an element.
pub fn rcm_order(mesh: &Mesh) -> Vec<u32> {
    let n = mesh.n_nodes();
    let mut adj: Vec<Vec<u32>> = vec![Vec::new(); n];
    for e in &mesh.elements {
        for &a in e {
            adj[a as usize].extend_from_slice(e);
        }
    }
    let (mut indptr, mut indices) = (Vec::with_capacity(n + 1), Vec::new());
    indptr.push(0usize);
    for a in &mut adj {
        a.sort_unstable();
        a.dedup();
        indices.extend(a.iter().map(|&b| b as usize));
        indptr.push(indices.len());
        *a = Vec::new();
    }
    let data = vec![1u8; indices.len()];
    let graph = sprs::CsMat::new((n, n), indptr, indices, data);
    let ordering = sprs::linalg::reverse_cuthill_mckee(graph.view());
    ordering.perm.vec().into_iter().map(|i| i as u32).collect()
}

/// A seeded random order of the nodes (Fisher-Yates with xorshift64*): `order[new] = old`.
pub fn shuffled_order(n: usize, seed: u64) -> Vec<u32> {
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut s = seed | 1;
    for i in (1..n).rev() {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        let r = s.wrapping_mul(0x2545_f491_4f6c_dd1d);
        order.swap(i, (r % (i as u64 + 1)) as usize);
    }
    order
}

/// Renumber the mesh's nodes: new node `k` is old node `order[k]`. Coordinates, connectivity
/// and node sets follow; elements keep their numbers.
pub fn apply(mesh: &mut Mesh, order: &[u32]) {
    assert_eq!(
        order.len(),
        mesh.n_nodes(),
        "a node order lists every node once"
    );
    let mut new_of_old = vec![u32::MAX; order.len()];
    for (new, &old) in order.iter().enumerate() {
        new_of_old[old as usize] = new as u32;
    }
    assert!(
        new_of_old.iter().all(|&k| k != u32::MAX),
        "a node order lists every node once"
    );
    mesh.nodes = order.iter().map(|&old| mesh.nodes[old as usize]).collect();
    for e in &mut mesh.elements {
        for a in e.iter_mut() {
            *a = new_of_old[*a as usize];
        }
    }
    for set in mesh.node_sets.values_mut() {
        for a in set.iter_mut() {
            *a = new_of_old[*a as usize];
        }
        set.sort_unstable();
    }
}

/// Number the mesh's nodes as asked; returns the bandwidth before and after.
pub fn renumber(mesh: &mut Mesh, how: Numbering, seed: u64) -> (u32, u32) {
    let before = bandwidth(mesh);
    match how {
        Numbering::AsGiven => {}
        Numbering::Rcm => {
            let order = rcm_order(mesh);
            apply(mesh, &order);
        }
        Numbering::Shuffled => {
            let order = shuffled_order(mesh.n_nodes(), seed);
            apply(mesh, &order);
        }
    }
    (before, bandwidth(mesh))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{box_mesh, BoxSpec};

    fn block() -> Mesh {
        box_mesh(
            &BoxSpec {
                divisions: [12, 10, 8],
                ..BoxSpec::default()
            },
            "body",
        )
        .unwrap()
    }

    /// The same geometry element by element, whatever the numbering.
    fn same_elements(a: &Mesh, b: &Mesh) -> bool {
        a.elements
            .iter()
            .zip(&b.elements)
            .all(|(ea, eb)| (0..8).all(|k| a.nodes[ea[k] as usize] == b.nodes[eb[k] as usize]))
    }

    #[test]
    fn shuffling_spreads_the_nodes_and_rcm_gathers_them_again() {
        let raster = block();
        let b0 = bandwidth(&raster);
        // the raster block's bandwidth: one layer of (13 x 11) nodes and one row and node more
        assert_eq!(b0, 13 * 11 + 13 + 1);
        let mut m = raster.clone();
        let (_, shuffled) = renumber(&mut m, Numbering::Shuffled, 7);
        // (1287 nodes: a random order puts some element's nodes nearly the whole range apart)
        assert!(shuffled > 5 * b0, "shuffled: {shuffled} against {b0}");
        assert!(same_elements(&raster, &m));
        let (_, rcm) = renumber(&mut m, Numbering::Rcm, 0);
        // RCM's level sets of a 13 x 11 x 9 grid are diagonal planes, larger than the raster's
        // layers of 143 nodes; its bandwidth stays within twice the raster's (234 measured)
        assert!(rcm <= 2 * b0, "rcm: {rcm} against {b0}");
        assert!(same_elements(&raster, &m));
        // node sets follow their nodes
        for (name, set) in &raster.node_sets {
            let mut want: Vec<[f64; 3]> = set.iter().map(|&a| raster.nodes[a as usize]).collect();
            let mut got: Vec<[f64; 3]> = m.node_sets[name]
                .iter()
                .map(|&a| m.nodes[a as usize])
                .collect();
            let key = |p: &[f64; 3]| (p[0].to_bits(), p[1].to_bits(), p[2].to_bits());
            want.sort_by_key(key);
            got.sort_by_key(key);
            assert_eq!(want, got, "node set {name}");
        }
    }

    #[test]
    fn numbering_labels_round_trip_and_unknown_ones_are_named() {
        for n in [Numbering::AsGiven, Numbering::Rcm, Numbering::Shuffled] {
            assert_eq!(Numbering::parse(n.label()), Ok(n));
        }
        let e = Numbering::parse("metis").unwrap_err();
        assert!(e.contains("metis") && e.contains("rcm"), "{e}");
    }
}
