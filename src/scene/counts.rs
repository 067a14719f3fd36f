//! Voxels per palette index, kept up to date by builds and every edit, so
//! the renderer knows which materials a scene holds (and so which effects it
//! needs) without walking the tree.

use crate::gpu_pool::{NodePool, is_pointer, slot_of};

/// Solid voxels of each palette index; index 0 (empty) is never counted.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VoxelCounts(Box<[u64; 256]>);

impl Default for VoxelCounts {
    fn default() -> VoxelCounts {
        VoxelCounts(Box::new([0; 256]))
    }
}

impl VoxelCounts {
    pub fn get(&self, index: u8) -> u64 {
        self.0[usize::from(index)]
    }

    /// All solid voxels.
    pub fn solid(&self) -> u64 {
        self.0[1..].iter().sum()
    }

    /// The palette indices that at least one voxel uses.
    pub fn present(&self) -> impl Iterator<Item = u8> + '_ {
        (1..=255u8).filter(|i| self.get(*i) > 0)
    }

    pub(crate) fn add(&mut self, index: u8, n: u64) {
        if index != 0 {
            self.0[usize::from(index)] += n;
        }
    }

    pub(crate) fn remove(&mut self, index: u8, n: u64) {
        if index != 0 {
            let count = &mut self.0[usize::from(index)];
            *count = count.saturating_sub(n);
        }
    }

    pub(crate) fn add_counts(&mut self, other: &VoxelCounts) {
        self.0.iter_mut().zip(other.0.iter()).for_each(|(a, b)| *a += b);
    }

    /// Counts every voxel under a child word of `level`.
    pub(crate) fn add_word(&mut self, pool: &NodePool, word: u32, level: u32) {
        tally(pool, word, level, &mut |index, n| self.add(index, n));
    }

    /// Uncounts every voxel under a child word of `level`.
    pub(crate) fn remove_word(&mut self, pool: &NodePool, word: u32, level: u32) {
        tally(pool, word, level, &mut |index, n| self.remove(index, n));
    }
}

/// Calls `f(index, voxels)` for the uniform cells and brick voxels under a
/// child word (empty ones included; the counts skip index 0).
fn tally(pool: &NodePool, word: u32, level: u32, f: &mut impl FnMut(u8, u64)) {
    if !is_pointer(word) {
        f(word as u8, 1u64 << (3 * level));
    } else if level == 1 {
        pool.bricks.get(slot_of(word)).iter().for_each(|v| f(*v, 1));
    } else {
        for &child in &pool.nodes.get(slot_of(word)).children {
            tally(pool, child, level - 1, f);
        }
    }
}
