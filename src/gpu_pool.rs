//! The node pool: the octree's storage, laid out exactly as the GPU reads it.
//!
//! CPU node *i* is GPU node slot *i* (and likewise for bricks), so the list of
//! slots an edit touched is the list of byte ranges to write. Nothing here
//! knows wgpu: [`NodePool::flush`] yields `(offset, bytes)` ranges and the
//! renderer hands them to `queue.write_buffer`. The layout is described in
//! `docs/node-format.md`.

/// Words in an interior node slot: one child word per octant, then the
/// node's level-of-detail summary (see [`NodeSlot`]).
pub const NODE_WORDS: usize = 9;
/// Word of a node slot that holds its level-of-detail summary.
pub const LOD_WORD: usize = 8;
/// Bytes of one interior node slot on the GPU.
pub const NODE_BYTES: u64 = 4 * NODE_WORDS as u64;
/// Bytes of one brick slot (2×2×2 palette indices) on the GPU.
pub const BRICK_BYTES: u64 = 8;

/// Child-word bit marking a pointer; the low 31 bits are a slot index.
/// Without it, the word is a uniform palette index (0 = empty).
pub const POINTER_BIT: u32 = 0x8000_0000;

/// An interior node's children: eight child words, octant `x | y << 1 | z << 2`.
pub type Node = [u32; 8];

/// A node slot as the GPU reads it: the children, then the subtree's
/// summary for level of detail (`crate::scene::lod`): its representative
/// palette index in the low byte, its coverage (solid fraction × 255,
/// rounded up) in the next. A traversal that stops early at this node shades
/// it as a solid cell of that index.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct NodeSlot {
    pub children: Node,
    pub lod: u32,
}

const _: () = assert!(std::mem::size_of::<NodeSlot>() == NODE_BYTES as usize);
/// A leaf brick: eight palette indices, octant `x | y << 1 | z << 2`.
pub type Brick = [u8; 8];

/// True when a child word points at a node or brick slot.
pub fn is_pointer(word: u32) -> bool {
    word & POINTER_BIT != 0
}

/// The slot index a pointer word refers to.
pub fn slot_of(word: u32) -> u32 {
    word & !POINTER_BIT
}

/// A pointer word for `slot`.
pub fn pointer_to(slot: u32) -> u32 {
    slot | POINTER_BIT
}

/// Slot state: whether the GPU copy is stale, and whether it is in use at all.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum SlotState {
    Clean,
    Dirty,
    Free,
}

/// A growable array of fixed-size slots with a free list and dirty tracking.
#[derive(Clone, Debug)]
pub struct SlotArena<T> {
    items: Vec<T>,
    state: Vec<SlotState>,
    free: Vec<u32>,
    dirty: Vec<u32>,
    /// Slots the GPU buffer can hold; `None` before the first flush.
    gpu_capacity: Option<usize>,
}

impl<T> Default for SlotArena<T> {
    fn default() -> Self {
        SlotArena { items: Vec::new(), state: Vec::new(), free: Vec::new(), dirty: Vec::new(), gpu_capacity: None }
    }
}

impl<T: bytemuck::Pod> SlotArena<T> {
    /// An arena holding `items` in slots 0.., all in use and all dirty (the
    /// first flush uploads them).
    pub fn from_items(items: Vec<T>) -> SlotArena<T> {
        let n = items.len();
        SlotArena {
            items,
            state: vec![SlotState::Dirty; n],
            free: Vec::new(),
            dirty: (0..n as u32).collect(),
            gpu_capacity: None,
        }
    }

    /// Stores `item` in a free slot (reusing freed ones first) and marks it dirty.
    pub fn alloc(&mut self, item: T) -> u32 {
        if let Some(slot) = self.free.pop() {
            self.items[slot as usize] = item;
            self.state[slot as usize] = SlotState::Clean;
            self.mark_dirty(slot);
            return slot;
        }
        let slot = u32::try_from(self.items.len()).unwrap_or(u32::MAX);
        assert!(slot < POINTER_BIT, "node pool exhausted (2^31 slots)");
        self.items.push(item);
        self.state.push(SlotState::Clean);
        self.mark_dirty(slot);
        slot
    }

    /// Returns a slot to the free list. Its GPU bytes are left as they are:
    /// nothing points at them any more.
    pub fn free(&mut self, slot: u32) {
        debug_assert!(self.state[slot as usize] != SlotState::Free, "double free of slot {slot}");
        self.state[slot as usize] = SlotState::Free;
        self.free.push(slot);
    }

    pub fn get(&self, slot: u32) -> &T {
        &self.items[slot as usize]
    }

    /// Overwrites a slot and marks it dirty.
    pub fn set(&mut self, slot: u32, item: T) {
        self.items[slot as usize] = item;
        self.mark_dirty(slot);
    }

    fn mark_dirty(&mut self, slot: u32) {
        if self.state[slot as usize] == SlotState::Clean {
            self.state[slot as usize] = SlotState::Dirty;
            self.dirty.push(slot);
        }
    }

    /// Slots in use.
    pub fn live(&self) -> usize {
        self.items.len() - self.free.len()
    }

    /// Slots ever allocated (the high-water mark the GPU buffer must hold).
    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    pub fn is_free(&self, slot: u32) -> bool {
        self.state.get(slot as usize).is_none_or(|s| *s == SlotState::Free)
    }

    /// All slots as one byte slice, in GPU layout.
    pub fn bytes(&self) -> &[u8] {
        bytemuck::cast_slice(&self.items)
    }

    /// The slots the GPU buffer should be re-created with, when it cannot
    /// hold the arena: half again as many as are in use, so a long session
    /// does not grow on every edit.
    /// Forgets what any GPU buffer holds: every slot in use is dirty and
    /// the next flush sizes a buffer afresh.
    fn forget_uploads(&mut self) {
        self.dirty.clear();
        for (slot, state) in (0..).zip(self.state.iter_mut()) {
            if *state != SlotState::Free {
                *state = SlotState::Dirty;
                self.dirty.push(slot);
            }
        }
        self.gpu_capacity = None;
    }

    fn wanted_capacity(&self) -> Option<usize> {
        match self.gpu_capacity {
            Some(cap) if cap >= self.items.len() => None,
            _ => Some((self.items.len() + self.items.len() / 2).max(1024)),
        }
    }

    /// Takes the dirty slots, coalesced into runs of consecutive slots; the
    /// GPU buffer is re-created with `capacity` slots when one is given.
    fn take_dirty(&mut self, capacity: Option<usize>) -> Region {
        let mut slots = std::mem::take(&mut self.dirty);
        slots.sort_unstable();
        let mut runs: Vec<(u32, u32)> = Vec::new();
        for slot in slots {
            if self.state[slot as usize] != SlotState::Dirty {
                continue; // freed after it was dirtied: nobody reads it
            }
            self.state[slot as usize] = SlotState::Clean;
            match runs.last_mut() {
                Some((_, end)) if *end == slot => *end += 1,
                _ => runs.push((slot, slot + 1)),
            }
        }
        if capacity.is_some() {
            self.gpu_capacity = capacity;
        }
        Region { slot_bytes: std::mem::size_of::<T>() as u64, grow_to_slots: capacity, runs }
    }
}

/// What one arena needs written after a flush.
#[derive(Clone, Debug, Default)]
pub struct Region {
    slot_bytes: u64,
    /// New capacity in slots when the buffer must be re-created (copy the old
    /// contents across, then write the runs).
    pub grow_to_slots: Option<usize>,
    /// Half-open slot ranges whose bytes changed.
    runs: Vec<(u32, u32)>,
}

impl Region {
    /// `(byte offset, bytes)` for each changed range.
    pub fn ranges<'a, T: bytemuck::Pod>(
        &'a self,
        arena: &'a SlotArena<T>,
    ) -> impl Iterator<Item = (u64, &'a [u8])> + 'a {
        self.runs.iter().map(move |&(start, end)| {
            let bytes = bytemuck::cast_slice(&arena.items[start as usize..end as usize]);
            (u64::from(start) * self.slot_bytes, bytes)
        })
    }

    /// Bytes the ranges cover.
    pub fn byte_count(&self) -> u64 {
        self.runs.iter().map(|&(s, e)| u64::from(e - s) * self.slot_bytes).sum()
    }

    pub fn range_count(&self) -> usize {
        self.runs.len()
    }

    pub fn grow_to_bytes(&self) -> Option<u64> {
        self.grow_to_slots.map(|slots| slots as u64 * self.slot_bytes)
    }
}

/// The changes of one flush: a region per arena.
#[derive(Clone, Debug, Default)]
pub struct Upload {
    pub nodes: Region,
    pub bricks: Region,
}

impl Upload {
    pub fn byte_count(&self) -> u64 {
        self.nodes.byte_count() + self.bricks.byte_count()
    }
}

/// Counters shown in the stats panel and read by tests and `expect written`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PoolStats {
    pub last_flush_bytes: u64,
    pub total_bytes: u64,
    pub last_flush_ranges: usize,
    pub flushes: u64,
    /// Times a GPU buffer had to be re-created larger.
    pub growths: u64,
}

/// Interior nodes and leaf bricks, each in its own arena (and GPU buffer).
#[derive(Clone, Debug, Default)]
pub struct NodePool {
    pub nodes: SlotArena<NodeSlot>,
    pub bricks: SlotArena<Brick>,
    pub stats: PoolStats,
}

/// A pool too large for one GPU buffer binding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("the scene's node pool needs {needed} bytes; this GPU binds at most {limit} bytes in one buffer")]
pub struct PoolTooLarge {
    pub needed: u64,
    pub limit: u64,
}

impl NodePool {
    /// The pool is going to a GPU buffer that holds none of it (a scene put
    /// in place of another, which may have been flushed elsewhere: a journal
    /// recovered headless): the next flush uploads every slot in use.
    pub fn forget_uploads(&mut self) {
        self.nodes.forget_uploads();
        self.bricks.forget_uploads();
    }

    /// Takes every change since the last flush. The caller writes each range
    /// (after re-creating a buffer that must grow) and nothing else.
    pub fn flush(&mut self) -> Upload {
        let capacities = (self.nodes.wanted_capacity(), self.bricks.wanted_capacity());
        self.take(capacities)
    }

    /// [`NodePool::flush`] for a GPU whose one buffer holds at most
    /// `max_bytes` (nodes and bricks share it): the headroom shrinks to fit,
    /// and a pool whose live slots alone do not fit is refused, its changes
    /// kept for a later flush.
    ///
    /// # Errors
    /// [`PoolTooLarge`] when the slots in use exceed `max_bytes`.
    pub fn flush_within(&mut self, max_bytes: u64) -> Result<Upload, PoolTooLarge> {
        let (nodes, bricks) = (self.nodes.wanted_capacity(), self.bricks.wanted_capacity());
        if nodes.is_none() && bricks.is_none() {
            return Ok(self.take((None, None)));
        }
        let bytes = |n: usize, b: usize| n as u64 * NODE_BYTES + b as u64 * BRICK_BYTES;
        // What the buffer holds after this flush: the new capacity, else the current one.
        let planned =
            (nodes.or(self.nodes.gpu_capacity).unwrap_or(0), bricks.or(self.bricks.gpu_capacity).unwrap_or(0));
        if bytes(planned.0, planned.1) <= max_bytes {
            return Ok(self.take((nodes, bricks)));
        }
        let used = (self.nodes.len(), self.bricks.len());
        let needed = bytes(used.0, used.1);
        if needed > max_bytes {
            return Err(PoolTooLarge { needed, limit: max_bytes });
        }
        // Both re-created, what is in use plus half each of what is left.
        let spare = max_bytes - needed;
        let fitted = (used.0 + (spare / 2 / NODE_BYTES) as usize, used.1 + (spare / 2 / BRICK_BYTES) as usize);
        Ok(self.take((Some(fitted.0), Some(fitted.1))))
    }

    fn take(&mut self, (nodes, bricks): (Option<usize>, Option<usize>)) -> Upload {
        let upload = Upload { nodes: self.nodes.take_dirty(nodes), bricks: self.bricks.take_dirty(bricks) };
        let bytes = upload.byte_count();
        self.stats.last_flush_bytes = bytes;
        self.stats.total_bytes += bytes;
        self.stats.last_flush_ranges = upload.nodes.range_count() + upload.bricks.range_count();
        self.stats.flushes += 1;
        self.stats.growths +=
            u64::from(upload.nodes.grow_to_slots.is_some()) + u64::from(upload.bricks.grow_to_slots.is_some());
        upload
    }

    /// Bytes of the live slots (what the tree needs, not counting free slots).
    pub fn live_bytes(&self) -> u64 {
        self.nodes.live() as u64 * NODE_BYTES + self.bricks.live() as u64 * BRICK_BYTES
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pool(nodes: usize, bricks: usize) -> NodePool {
        let mut pool = NodePool::default();
        for _ in 0..nodes {
            pool.nodes.alloc(NodeSlot { children: [1; 8], lod: 0 });
        }
        for _ in 0..bricks {
            pool.bricks.alloc([1; 8]);
        }
        pool
    }

    fn bytes(upload: &Upload) -> u64 {
        upload.nodes.grow_to_bytes().unwrap_or(0) + upload.bricks.grow_to_bytes().unwrap_or(0)
    }

    /// The 4096-tall statue's pool fitted lavapipe's binding but its
    /// headroom did not, and every frame failed validation.
    #[test]
    fn the_headroom_shrinks_to_fit_one_binding() {
        let mut roomy = pool(2000, 4000);
        let upload = roomy.flush_within(u64::MAX).unwrap();
        assert_eq!(upload.nodes.grow_to_slots, Some(3000), "half again as many slots when there is room");
        let used = 2000 * NODE_BYTES + 4000 * BRICK_BYTES;
        let mut tight = pool(2000, 4000);
        let limit = used + used / 10;
        let upload = tight.flush_within(limit).unwrap();
        assert!(bytes(&upload) <= limit && bytes(&upload) >= used, "{} of {limit}", bytes(&upload));
        assert_eq!(upload.byte_count(), used, "every slot is still written");
    }

    #[test]
    fn a_pool_past_the_binding_is_refused_and_kept_for_later() {
        let mut big = pool(100, 100);
        let err = big.flush_within(100).unwrap_err();
        assert_eq!(err, PoolTooLarge { needed: 100 * NODE_BYTES + 100 * BRICK_BYTES, limit: 100 });
        let upload = big.flush_within(u64::MAX).unwrap();
        assert_eq!(upload.byte_count(), 100 * NODE_BYTES + 100 * BRICK_BYTES, "nothing was lost");
    }
}
