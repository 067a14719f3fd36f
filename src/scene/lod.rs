//! Level-of-detail summaries: what a subtree looks like from far away.
//!
//! Every node slot carries one summary word beside its children
//! ([`crate::gpu_pool::NodeSlot`]): a representative palette index and the
//! subtree's coverage. A traversal with a pixel footprint stops at a node
//! whose cell is smaller than the footprint and shades it as a solid cell of
//! that index (Laine & Karras's cut-off, without their contours).
//!
//! The summary holds a palette *index*, not a colour, so it does not depend
//! on the palette: editing a colour or a material changes no node, and a
//! far cell keeps its material (an emitter still emits). The price is that a
//! fine mix of colours shows its most common one rather than its average.
//!
//! A node's summary comes from its eight children alone, so an edit updates
//! the nodes on its path and nothing else: builds, brushes and undo all make
//! nodes through [`Octree::make_node`](super::Octree), which computes it.

use crate::gpu_pool::{Brick, is_pointer};

/// What a cell looks like from far away.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Summary {
    /// The palette index covering the most of the cell (0 when empty).
    pub index: u8,
    /// Solid fraction of the cell × 255, rounded up: 0 only when empty.
    pub coverage: u8,
}

impl Summary {
    /// A uniform cell of palette index `value`.
    pub fn uniform(value: u8) -> Summary {
        Summary { index: value, coverage: if value == 0 { 0 } else { 255 } }
    }

    /// The word stored in a node slot.
    pub fn word(self) -> u32 {
        u32::from(self.index) | u32::from(self.coverage) << 8
    }

    pub fn from_word(word: u32) -> Summary {
        Summary { index: word as u8, coverage: (word >> 8) as u8 }
    }

    /// A brick's eight voxels.
    pub fn of_brick(brick: &Brick) -> Summary {
        combine(brick.map(Summary::uniform))
    }
}

/// The summary of the cell of child word `word` at `level`: a uniform
/// word's own, a brick's from its voxels (`brick` reads it), a node's as
/// stored in its slot (`node_lod` reads the summary word). One rule for the
/// octree's pool and a build's local arena.
pub fn of_word(word: u32, level: u32, brick: impl FnOnce(u32) -> Brick, node_lod: impl FnOnce(u32) -> u32) -> Summary {
    if !is_pointer(word) {
        Summary::uniform(word as u8)
    } else if level == 1 {
        Summary::of_brick(&brick(word))
    } else {
        Summary::from_word(node_lod(word))
    }
}

/// The summary of a cell from its eight children's: the index with the most
/// coverage (ties to the lower index), and the mean coverage.
pub fn combine(children: [Summary; 8]) -> Summary {
    let mut weights: [(u8, u32); 8] = [(0, 0); 8];
    let mut used = 0;
    for child in children.iter().filter(|c| c.index != 0) {
        match weights[..used].iter_mut().find(|w| w.0 == child.index) {
            Some(w) => w.1 += u32::from(child.coverage),
            None => {
                weights[used] = (child.index, u32::from(child.coverage));
                used += 1;
            }
        }
    }
    let best = weights[..used].iter().fold((0u8, 0u32), |best, &(index, weight)| {
        if weight > best.1 || (weight == best.1 && index < best.0) { (index, weight) } else { best }
    });
    let total: u32 = children.iter().map(|c| u32::from(c.coverage)).sum();
    Summary { index: best.0, coverage: total.div_ceil(8) as u8 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_index_covering_most_wins() {
        let brick: Brick = [0, 3, 3, 5, 5, 5, 0, 0];
        assert_eq!(Summary::of_brick(&brick), Summary { index: 5, coverage: 160 });
        let mut children = [Summary::default(); 8];
        children[0] = Summary::uniform(7);
        children[1] = Summary { index: 2, coverage: 200 };
        children[2] = Summary { index: 2, coverage: 100 };
        assert_eq!(combine(children), Summary { index: 2, coverage: 70 });
    }

    #[test]
    fn ties_go_to_the_lower_index_and_any_voxel_counts() {
        let brick: Brick = [9, 4, 0, 0, 0, 0, 0, 0];
        assert_eq!(Summary::of_brick(&brick), Summary { index: 4, coverage: 64 });
        let mut children = [Summary::default(); 8];
        children[5] = Summary { index: 1, coverage: 1 };
        assert_eq!(combine(children).coverage, 1, "a non-empty cell never reads as empty");
        assert_eq!(combine([Summary::default(); 8]), Summary::default());
    }
}
