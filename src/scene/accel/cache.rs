//! Built trees kept on disk: a mesh of tens of thousands of triangles or more loads again faster when its tree is
//! read back rather than built (the 67 200-triangle knot's build, PLOC and the collapse to eight wide, is about
//! 25 ms of its 45 ms load; a 1M-triangle grid loads in 0.4 s instead of 0.8 s). Dr.Jit keeps Mitsuba's compiled
//! kernels on disk the same way.
//!
//! An entry is found by a 128-bit XXH3 hash of everything the build reads: the triangles' positions and groups,
//! this format's version and the program's identity ([`DiskCache::hasher`]), so a rebuilt or upgraded illumlab
//! never reads a tree another build made. An entry holds the nodes, their children's
//! groups, the number of triangles in each packet and the order, then their XXH3 checksum; the packets are made
//! again from the positions. Its structure is checked when it is read (every node and packet reached once from the
//! root, every index in range, the order a permutation): a file that fails any check is ignored and written again.
//!
//! Where: `trees` in the user's cache folder ([`DiskCache::in_user_cache`]).

use super::Accel;
use super::node::{Child, ChildGroups, Node8};
use super::packet::TrianglePacket;
use crate::scene::disk_cache::{DiskCache, check_sum, entry_head, write_sections};
use glam::Vec3;
use rayon::prelude::*;
use std::io::{Read, Write};
use std::path::PathBuf;
use std::sync::OnceLock;

/// Meshes with fewer triangles are built every time: their build takes a few milliseconds or less.
pub const MIN_TRIANGLES: usize = 16_384;

/// Raised whenever an entry's layout changes (a change of the build is a change of the program's identity).
const FORMAT: u32 = 1;

/// The first four words of an entry: "illumlab tree" and three zero bytes.
const MAGIC: [u8; 16] = *b"illumlab tree\0\0\0";

/// A folder of built trees.
#[derive(Clone, Debug)]
pub struct TreeCache {
    disk: DiskCache,
}

impl TreeCache {
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self { disk: DiskCache::new(dir, "tree") }
    }

    /// `trees` in the user's cache folder, unless the environment turns caches off ([`DiskCache::in_user_cache`]);
    /// read once per process.
    pub fn from_env() -> Option<&'static TreeCache> {
        static CACHE: OnceLock<Option<TreeCache>> = OnceLock::new();
        CACHE.get_or_init(|| DiskCache::in_user_cache("trees", "tree").map(|disk| TreeCache { disk })).as_ref()
    }

    /// The key of the tree [`Accel::build`] makes of `positions` and `groups`.
    pub fn key(positions: &[[Vec3; 3]], groups: &[Option<u32>]) -> u128 {
        let mut hash = DiskCache::hasher();
        hash.update(&MAGIC);
        hash.update(&FORMAT.to_le_bytes());
        hash.update(&(positions.len() as u64).to_le_bytes());
        hash.update(bytemuck::cast_slice(positions));
        for chunk in groups.chunks(4096) {
            let words: Vec<u32> = chunk.iter().map(|g| g.unwrap_or(u32::MAX)).collect();
            hash.update(bytemuck::cast_slice(&words));
        }
        hash.digest128()
    }

    /// The tree stored under `key` for the triangles `positions`, with its order, if there is a sound one.
    pub fn load(&self, key: u128, positions: &[[Vec3; 3]]) -> Option<(Accel, Vec<u32>)> {
        let (mut file, bytes) = self.disk.open(key)?;
        read_entry(&mut file, bytes, key, positions)
    }

    /// Stores `tree` and `order` under `key`.
    pub fn store(&self, key: u128, tree: &Accel, order: &[u32]) -> std::io::Result<()> {
        self.disk.store(key, |out| write_entry(out, key, tree, order))
    }
}

/// The words before the sections: magic (4), format, key (4), triangles, nodes, packets, root (first, packets,
/// present), and one of padding.
const HEADER_WORDS: usize = 16;

fn header(key: u128, tree: &Accel, triangles: usize) -> [u32; HEADER_WORDS] {
    let mut words = [0; HEADER_WORDS];
    words[..9].copy_from_slice(&entry_head(MAGIC, FORMAT, key));
    let root = tree.root.unwrap_or_default();
    let (nodes, packets) = (tree.nodes.len() as u32, tree.packets.len() as u32);
    words[9..15].copy_from_slice(&[
        triangles as u32,
        nodes,
        packets,
        root.first,
        root.packets,
        tree.root.is_some() as u32,
    ]);
    words
}

/// The number of triangles in each packet, as bytes padded to whole words. A packet holds the stored triangles
/// after its predecessors' (see `build::Builder::leaf`), so the lengths and the order give back the packets.
fn packet_lengths(tree: &Accel) -> Vec<u8> {
    let mut lengths: Vec<u8> =
        tree.packets.iter().map(|p| p.ids.iter().filter(|&&id| id != u32::MAX).count() as u8).collect();
    lengths.resize(lengths.len().next_multiple_of(4), 0);
    lengths
}

/// An entry's sections in order, as bytes: the header, the nodes, their children's groups, the packets' lengths
/// and the order; the file ends with their XXH3 checksum. The packets themselves (320 bytes for up to eight
/// triangles) are made again from the positions: 3.5 times less to write and read.
fn sections<'a>(
    header: &'a [u32; HEADER_WORDS],
    tree: &'a Accel,
    lengths: &'a [u8],
    order: &'a [u32],
) -> [&'a [u8]; 5] {
    [
        bytemuck::cast_slice(header),
        bytemuck::cast_slice(&tree.nodes),
        bytemuck::cast_slice(&tree.groups),
        lengths,
        bytemuck::cast_slice(order),
    ]
}

fn write_entry(file: &mut dyn Write, key: u128, tree: &Accel, order: &[u32]) -> std::io::Result<()> {
    let (header, lengths) = (header(key, tree, order.len()), packet_lengths(tree));
    write_sections(file, &sections(&header, tree, &lengths, order))
}

/// The tree in `file` (of `bytes` bytes), if it is an entry of this format for `key` over `positions`, whole,
/// and its structure is sound. Each section is read straight into its vector; the packets are made again.
fn read_entry(file: &mut impl Read, bytes: u64, key: u128, positions: &[[Vec3; 3]]) -> Option<(Accel, Vec<u32>)> {
    let triangles = positions.len();
    let mut head = [0u32; HEADER_WORDS];
    file.read_exact(bytemuck::cast_slice_mut(&mut head)).ok()?;
    let [n, nodes, packets, first, leaf_packets, present] = head[9..15].try_into().ok()?;
    if head[..9] != entry_head(MAGIC, FORMAT, key)
        || head[15] != 0
        || n as usize != triangles
        || nodes as usize > triangles
        || packets as usize > triangles
    {
        return None;
    }
    let (nodes, packets) = (nodes as usize, packets as usize);
    let expected = size_of_val(&head)
        + nodes * (size_of::<Node8>() + size_of::<ChildGroups>())
        + packets.next_multiple_of(4)
        + triangles * 4
        + 8;
    if bytes != expected as u64 {
        return None;
    }
    let mut read = |bytes: &mut [u8]| file.read_exact(bytes).ok();
    let mut tree = Accel {
        nodes: bytemuck::zeroed_vec(nodes),
        groups: bytemuck::zeroed_vec(nodes),
        packets: Vec::new(),
        root: (present == 1).then_some(Child { first, packets: leaf_packets }),
        depth: 0,
        from_cache: true,
    };
    let mut lengths = vec![0u8; packets.next_multiple_of(4)];
    let mut order: Vec<u32> = bytemuck::zeroed_vec(triangles);
    read(bytemuck::cast_slice_mut(&mut tree.nodes))?;
    read(bytemuck::cast_slice_mut(&mut tree.groups))?;
    read(&mut lengths)?;
    read(bytemuck::cast_slice_mut(&mut order))?;
    check_sum(file, &sections(&head, &tree, &lengths, &order))?;
    permutation(&order, triangles)?;
    tree.packets = packets_again(&lengths[..packets], &order, positions)?;
    tree.depth = sound_depth(&tree)?;
    Some((tree, order))
}

/// The packets of `lengths` triangles each, in order, as the build made them, if the lengths (1 to 8) add up to
/// the triangles.
fn packets_again(lengths: &[u8], order: &[u32], positions: &[[Vec3; 3]]) -> Option<Vec<TrianglePacket>> {
    let firsts: Vec<usize> = lengths
        .iter()
        .scan(0, |next, &len| {
            let first = *next;
            *next += len as usize;
            Some(first)
        })
        .collect();
    let sound = lengths.iter().all(|len| (1..=8).contains(len));
    if !sound || firsts.last().map_or(0, |&f| f + lengths[lengths.len() - 1] as usize) != order.len() {
        return None;
    }
    let packet = |(&first, &len): (&usize, &u8)| {
        let stored = |i: usize| (positions[order[first + i] as usize], (first + i) as u32);
        TrianglePacket::from_fn(len as usize, stored)
    };
    Some(firsts.par_iter().zip(lengths).map(packet).collect())
}

/// The tree's depth (as [`Accel::build`] counts it), if every node and packet is reached once from the root,
/// every index is in range and every unused lane is empty.
fn sound_depth(tree: &Accel) -> Option<usize> {
    let Some(root) = tree.root else {
        return (tree.nodes.is_empty() && tree.packets.is_empty()).then_some(0);
    };
    let (mut node_seen, mut packet_seen) = (vec![false; tree.nodes.len()], vec![false; tree.packets.len()]);
    let mut stack = vec![(root, 0usize)];
    let mut depth = 0;
    while let Some((child, level)) = stack.pop() {
        if child.is_leaf() {
            let range = child.first as usize..child.first as usize + child.packets as usize;
            for seen in packet_seen.get_mut(range)? {
                if std::mem::replace(seen, true) {
                    return None;
                }
            }
            depth = depth.max(level);
            continue;
        }
        if std::mem::replace(node_seen.get_mut(child.first as usize)?, true) || level >= 64 {
            return None;
        }
        let node = &tree.nodes[child.first as usize];
        for (lane, &grandchild) in node.children.iter().enumerate() {
            if node.used() & (1 << lane) != 0 {
                stack.push((grandchild, level + 1));
            } else if node.bounds().iter().take(3).any(|lo| lo.as_array_ref()[lane] != f32::INFINITY)
                || node.bounds().iter().skip(3).any(|hi| hi.as_array_ref()[lane] != f32::NEG_INFINITY)
            {
                return None;
            }
        }
    }
    (node_seen.iter().all(|&s| s) && packet_seen.iter().all(|&s| s)).then_some(depth)
}

/// `Some` if `values` holds each of 0..n once.
fn permutation(values: &[u32], n: usize) -> Option<()> {
    let mut seen = vec![false; n];
    for &v in values {
        if std::mem::replace(seen.get_mut(v as usize)?, true) {
            return None;
        }
    }
    (values.len() == n).then_some(())
}

impl Accel {
    /// [`Accel::build`], through `cache` for a mesh of [`MIN_TRIANGLES`] or more: the stored tree if there is a
    /// sound one for this input, else a new one, stored (a failure to store only loses the time saved).
    pub fn build_cached(
        positions: &[[Vec3; 3]],
        groups: &[Option<u32>],
        cache: Option<&TreeCache>,
    ) -> (Self, Vec<u32>) {
        let Some(cache) = cache.filter(|_| positions.len() >= MIN_TRIANGLES) else {
            return Self::build(positions, groups);
        };
        let key = TreeCache::key(positions, groups);
        if let Some(tree) = cache.load(key, positions) {
            return tree;
        }
        let (tree, order) = Self::build(positions, groups);
        let _ = cache.store(key, &tree, &order);
        (tree, order)
    }

    /// Whether this tree was read from a [`TreeCache`] rather than built.
    pub fn from_cache(&self) -> bool {
        self.from_cache
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::SampleRng;
    use std::fs;

    /// `n` small triangles scattered in the unit cube, every fifth in group 7.
    fn soup(n: usize, seed: u64) -> (Vec<[Vec3; 3]>, Vec<Option<u32>>) {
        let mut rng = SampleRng::new(seed, 0, 0);
        let mut point = || Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
        let triangles = (0..n)
            .map(|_| {
                let a = point();
                [a, a + 0.01 * point(), a + 0.01 * point()]
            })
            .collect();
        (triangles, (0..n).map(|i| (i % 5 == 0).then_some(7)).collect())
    }

    /// The same tree: every node, group, packet and index bit for bit, the same root and depth.
    fn assert_same(a: &(Accel, Vec<u32>), b: &(Accel, Vec<u32>)) {
        let bytes = |t: &Accel| {
            let mut v: Vec<u8> = bytemuck::cast_slice(&t.nodes).to_vec();
            v.extend_from_slice(bytemuck::cast_slice(&t.groups));
            v
        };
        assert!(bytes(&a.0) == bytes(&b.0), "nodes or groups differ");
        // Debug prints each float's shortest round trip (and the sign of a zero): equal strings, equal bits.
        assert_eq!(format!("{:?}", a.0.packets), format!("{:?}", b.0.packets), "packets differ");
        assert_eq!((a.0.root, a.0.depth, &a.1), (b.0.root, b.0.depth, &b.1));
    }

    #[test]
    fn a_stored_tree_reads_back_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        let cache = TreeCache::new(dir.path());
        for n in [1, 9, 700, 5000] {
            let (positions, groups) = soup(n, n as u64);
            let key = TreeCache::key(&positions, &groups);
            let built = Accel::build(&positions, &groups);
            assert!(cache.load(key, &positions).is_none(), "nothing stored yet");
            cache.store(key, &built.0, &built.1).unwrap();
            let read = cache.load(key, &positions).expect("stored");
            assert!(read.0.from_cache() && !built.0.from_cache());
            assert_same(&read, &built);
            assert!(cache.load(key, &positions[1..]).is_none(), "another triangle count is another input");
        }
    }

    #[test]
    fn a_large_mesh_is_built_once_then_read() {
        let dir = tempfile::tempdir().unwrap();
        let cache = TreeCache::new(dir.path());
        let (positions, groups) = soup(MIN_TRIANGLES, 3);
        let first = Accel::build_cached(&positions, &groups, Some(&cache));
        let second = Accel::build_cached(&positions, &groups, Some(&cache));
        assert!(!first.0.from_cache() && second.0.from_cache());
        assert_same(&first, &second);
        let (small, small_groups) = soup(MIN_TRIANGLES - 1, 3);
        assert!(!Accel::build_cached(&small, &small_groups, Some(&cache)).0.from_cache());
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1, "a small mesh is not stored");
    }

    #[test]
    fn any_change_of_the_input_is_another_key() {
        let (mut positions, mut groups) = soup(100, 4);
        let key = TreeCache::key(&positions, &groups);
        groups[3] = Some(1);
        let regrouped = TreeCache::key(&positions, &groups);
        positions[99][2].x = positions[99][2].x.next_up();
        let moved = TreeCache::key(&positions, &groups);
        assert!(key != regrouped && regrouped != moved && key != moved);
    }

    #[test]
    fn a_damaged_entry_is_ignored_and_replaced() {
        let dir = tempfile::tempdir().unwrap();
        let cache = TreeCache::new(dir.path());
        let (positions, groups) = soup(2000, 5);
        let key = TreeCache::key(&positions, &groups);
        let built = Accel::build(&positions, &groups);
        cache.store(key, &built.0, &built.1).unwrap();
        let path = cache.disk.path(key);
        let good = fs::read(&path).unwrap();
        // One bit flipped anywhere (header, nodes, packet lengths, order, checksum), cut short, or made longer.
        for at in [0, 20, 64, 64 + 300, good.len() / 2, good.len() - 4 * 2000 - 11, good.len() - 1] {
            let mut bad = good.clone();
            bad[at] ^= 0x10;
            fs::write(&path, &bad).unwrap();
            assert!(cache.load(key, &positions).is_none(), "flipped at {at}");
        }
        for len in [0, 10, 64, good.len() - 8, good.len() - 1] {
            fs::write(&path, &good[..len]).unwrap();
            assert!(cache.load(key, &positions).is_none(), "cut at {len}");
        }
        fs::write(&path, [&good[..], &[0; 8]].concat()).unwrap();
        assert!(cache.load(key, &positions).is_none(), "longer");
        // Rebuilt and stored again over the damaged file.
        let (positions, groups) = soup(MIN_TRIANGLES, 6);
        let key = TreeCache::key(&positions, &groups);
        fs::write(cache.disk.path(key), b"not a tree").unwrap();
        let (tree, order) = Accel::build_cached(&positions, &groups, Some(&cache));
        assert!(!tree.from_cache());
        assert_same(&cache.load(key, &positions).expect("replaced"), &(tree, order));
    }

    #[test]
    fn an_entry_with_a_sound_checksum_but_an_unsound_tree_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let cache = TreeCache::new(dir.path());
        let (positions, groups) = soup(3000, 7);
        let key = TreeCache::key(&positions, &groups);
        let (tree, order) = Accel::build(&positions, &groups);
        let store = |tree: &Accel, order: &[u32]| {
            cache.store(key, tree, order).unwrap();
            cache.load(key, &positions)
        };
        assert!(store(&tree, &order).is_some());
        let mut swapped = order.clone();
        swapped[1] = swapped[0];
        assert!(store(&tree, &swapped).is_none(), "an order that is not a permutation");
        let mut outside = tree.clone();
        outside.nodes[0].children[0].first = 1 << 30;
        assert!(store(&outside, &order).is_none(), "a child out of range");
        let mut twice = tree.clone();
        twice.nodes[0].children[1] = twice.nodes[0].children[0];
        assert!(store(&twice, &order).is_none(), "a subtree reached twice");
        let mut short = tree.clone();
        short.packets[0].ids[1..].fill(u32::MAX);
        assert!(store(&short, &order).is_none(), "packets holding fewer triangles than the mesh");
    }
}
