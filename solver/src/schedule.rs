//! The element loop's schedule: every group's elements cut into chunks of [`CHUNK`], and the
//! chunks of all groups coloured together into passes, so that no two chunks of one pass share
//! a node.
//!
//! The chunks of a pass run in parallel, each adding its elements' nodal forces straight into
//! the nodal force array; the passes run one after the other. No two threads write one node at
//! once, and every node receives its contributions in the same order (pass, then element order
//! inside its chunk) whatever the thread count, so results are bitwise identical on 1 or N
//! threads.
//!
//! The passes span the groups (one law and formulation each) rather than colouring each group
//! on its own: a palpation has four or five parts, and group-by-group colouring gave the 5 mm
//! phantom eleven passes per step, several of them of one to three chunks, which two threads
//! cannot share evenly (a pass of three equal chunks keeps one thread idle a third of the time).
//! Colouring all chunks together needs about as many passes as the busiest node has parts
//! around it, and each pass mixes chunks of every part. Measured on `palpa palpate` (5 mm, 2
//! threads): see docs/performance.md, "The element loop's schedule".

use material::real::LANES;

/// Elements per parallel chunk (a multiple of [`LANES`]). Fixed, so partial sums are formed in
/// the same order for any thread count (bitwise determinism).
pub const CHUNK: usize = 256;

const _: () = assert!(CHUNK % LANES == 0);

/// One chunk of one group: elements `chunk * CHUNK ..` of group `group`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChunkId {
    /// Group index.
    pub group: u32,
    /// Chunk index inside the group.
    pub chunk: u32,
}

/// The passes of the element loop: each a list of chunks that share no node, in ascending
/// (group, chunk) order.
#[derive(Clone, Debug, Default)]
pub struct Schedule {
    /// The passes, run one after the other.
    pub passes: Vec<Vec<ChunkId>>,
}

impl Schedule {
    /// Colour the chunks of every group (`conns[g]` the connectivity of group `g`, elements in
    /// chunks of [`CHUNK`] in order) so that no two chunks of one pass share a node: greedy, in
    /// (group, chunk) order, each chunk taking the lowest pass that none of the earlier chunks
    /// it shares a node with has. A mesh numbered for locality (slabs of elements) needs a few
    /// passes.
    pub fn colour(conns: &[&[[u32; 8]]], n_nodes: usize) -> Schedule {
        // Global chunk numbers: group g's chunk c is offset[g] + c.
        let mut offset = Vec::with_capacity(conns.len() + 1);
        offset.push(0usize);
        for c in conns {
            offset.push(offset.last().unwrap() + c.len().div_ceil(CHUNK));
        }
        let n_chunks = *offset.last().unwrap();
        // For each node, the global chunks (ascending) that touch it.
        let mut node_chunks: Vec<Vec<u32>> = vec![Vec::new(); n_nodes];
        for (g, conn) in conns.iter().enumerate() {
            for (e, c) in conn.iter().enumerate() {
                let ci = (offset[g] + e / CHUNK) as u32;
                for &n in c {
                    let list = &mut node_chunks[n as usize];
                    if list.last() != Some(&ci) {
                        list.push(ci);
                    }
                }
            }
        }
        // Chunks in the order of their lowest node: a mesh numbered for locality gives each
        // chunk a narrow band of node numbers, the chunks that share nodes have overlapping
        // bands, and greedy colouring in the order of the bands' starts is what colours
        // intervals with the fewest colours (the most bands over any one node).
        let mut order: Vec<(u32, ChunkId)> = Vec::with_capacity(n_chunks);
        for (g, conn) in conns.iter().enumerate() {
            for (c, elems) in conn.chunks(CHUNK).enumerate() {
                let lowest = elems.iter().flatten().copied().min().unwrap_or(0);
                let id = ChunkId {
                    group: g as u32,
                    chunk: c as u32,
                };
                order.push((lowest, id));
            }
        }
        order.sort_by_key(|&(lowest, id)| (lowest, id.group, id.chunk));
        let mut pass_of = vec![u32::MAX; n_chunks];
        let mut passes: Vec<Vec<ChunkId>> = Vec::new();
        let mut taken: Vec<bool> = Vec::new();
        for &(_, id) in &order {
            let (g, c) = (id.group as usize, id.chunk as usize);
            let ci = offset[g] + c;
            taken.iter_mut().for_each(|t| *t = false);
            let elems = &conns[g][c * CHUNK..((c + 1) * CHUNK).min(conns[g].len())];
            for &n in elems.iter().flatten() {
                for &other in &node_chunks[n as usize] {
                    let p = pass_of[other as usize];
                    if p != u32::MAX {
                        taken[p as usize] = true;
                    }
                }
            }
            let k = taken.iter().position(|t| !t).unwrap_or(taken.len());
            if k == passes.len() {
                passes.push(Vec::new());
                taken.push(false);
            }
            pass_of[ci] = k as u32;
            passes[k].push(id);
        }
        for p in &mut passes {
            p.sort_by_key(|id| (id.group, id.chunk));
        }
        Schedule { passes }
    }

    /// The number of chunks, of passes, and the fewest chunks any pass has (the parallelism of
    /// the slowest pass).
    pub fn summary(&self) -> (usize, usize, usize) {
        let chunks = self.passes.iter().map(Vec::len).sum();
        let fewest = self.passes.iter().map(Vec::len).min().unwrap_or(0);
        (chunks, self.passes.len(), fewest)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Connectivity of an nx x ny x nz block of hexahedra (the box generator's, elements in
    /// x-fastest order) and its node count.
    fn block(nx: u32, ny: u32, nz: u32) -> (Vec<[u32; 8]>, usize) {
        let spec = crate::generate::BoxSpec {
            divisions: [nx as usize, ny as usize, nz as usize],
            ..Default::default()
        };
        let mesh = crate::generate::box_mesh(&spec, "block").unwrap();
        (mesh.elements, mesh.nodes.len())
    }

    /// Every chunk of every group in exactly one pass, no two chunks of a pass sharing a node,
    /// and each pass in ascending (group, chunk) order.
    fn assert_valid(conns: &[&[[u32; 8]]], n_nodes: usize, s: &Schedule) {
        let mut seen: Vec<Vec<u32>> = conns
            .iter()
            .map(|c| vec![0; c.len().div_ceil(CHUNK)])
            .collect();
        for pass in &s.passes {
            let mut owner = vec![None; n_nodes];
            for id in pass {
                seen[id.group as usize][id.chunk as usize] += 1;
                let (g, c) = (id.group as usize, id.chunk as usize);
                let conn = conns[g];
                for e in &conn[c * CHUNK..((c + 1) * CHUNK).min(conn.len())] {
                    for &n in e {
                        let o = &mut owner[n as usize];
                        assert!(
                            o.is_none() || *o == Some(*id),
                            "chunks {o:?} and {id:?} share node {n}"
                        );
                        *o = Some(*id);
                    }
                }
            }
            assert!(
                pass.windows(2)
                    .all(|w| (w[0].group, w[0].chunk) < (w[1].group, w[1].chunk)),
                "chunks in ascending order"
            );
        }
        assert!(seen.iter().flatten().all(|&s| s == 1), "every chunk once");
    }

    #[test]
    fn colouring_of_an_ordered_block_is_race_free_and_parallel() {
        let (conn, nn) = block(50, 50, 40);
        let s = Schedule::colour(&[&conn], nn);
        assert_valid(&[&conn], nn, &s);
        // Slabs of 256 elements in a 50 x 50 plane: a handful of passes, each with many chunks.
        let (_, passes, fewest) = s.summary();
        assert!(passes <= 6, "{passes} passes");
        assert!(fewest >= 40, "fewest {fewest}");
    }

    #[test]
    fn colouring_of_a_shuffled_block_is_still_race_free() {
        let (mut conn, nn) = block(20, 20, 20);
        // A fixed pseudo-random permutation of the elements (xorshift).
        let mut s = 0x9e37_79b9_7f4a_7c15u64;
        for i in (1..conn.len()).rev() {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            conn.swap(i, (s % (i as u64 + 1)) as usize);
        }
        let sched = Schedule::colour(&[&conn], nn);
        assert_valid(&[&conn], nn, &sched);
    }

    #[test]
    fn groups_sharing_nodes_are_coloured_together() {
        // One block split into three groups by layers: the groups share the nodes of the
        // layers between them, so their chunks must be in different passes there, and the
        // passes mix chunks of different groups.
        let (conn, nn) = block(30, 30, 30);
        let per = conn.len() / 3;
        let groups: Vec<&[[u32; 8]]> = conn.chunks(per).collect();
        let s = Schedule::colour(&groups, nn);
        assert_valid(&groups, nn, &s);
        let mixed = s
            .passes
            .iter()
            .any(|p| p.iter().any(|c| c.group != p[0].group));
        assert!(mixed, "some pass mixes groups");
        // Colouring the groups together needs fewer passes than colouring them one by one
        // (the passes the element loop had before, group after group).
        let alone: usize = groups
            .iter()
            .map(|g| Schedule::colour(&[g], nn).passes.len())
            .sum();
        assert!(s.passes.len() < alone, "{} >= {alone}", s.passes.len());
    }
}
