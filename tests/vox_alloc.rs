//! Hostile headers must not make the loader allocate what they claim.
//!
//! This test binary counts heap bytes with a wrapping global allocator, so it
//! holds a single test: nothing else allocates while it measures.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report
#![expect(unsafe_code, reason = "a GlobalAlloc that forwards to System needs unsafe impl")]

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use octovox::io::vox::load_vox;

struct PeakCounter;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is forwarded unchanged to `System`; the counters are
// only bookkeeping.
unsafe impl GlobalAlloc for PeakCounter {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
        PEAK.fetch_max(live, Ordering::Relaxed);
        // SAFETY: same contract as ours.
        unsafe { System.alloc(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: same contract as ours.
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static ALLOCATOR: PeakCounter = PeakCounter;

fn words(values: &[u32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

fn vox_file(chunks: &[(&[u8; 4], Vec<u8>)]) -> Vec<u8> {
    let mut children = Vec::new();
    for (id, content) in chunks {
        children.extend(*id);
        children.extend(words(&[u32::try_from(content.len()).expect("small"), 0]));
        children.extend(content);
    }
    let mut bytes = b"VOX ".to_vec();
    bytes.extend(words(&[150]));
    bytes.extend(b"MAIN");
    bytes.extend(words(&[0, u32::try_from(children.len()).expect("small")]));
    bytes.extend(children);
    bytes
}

/// Peak heap growth, in bytes, while loading `bytes` (which must fail).
fn peak_while_failing(bytes: &[u8]) -> usize {
    let before = LIVE.load(Ordering::Relaxed);
    PEAK.store(before, Ordering::Relaxed);
    assert!(load_vox(bytes, 0).is_err());
    PEAK.load(Ordering::Relaxed) - before
}

#[test]
fn hostile_headers_allocate_almost_nothing() {
    let one_voxel = words(&[1]).into_iter().chain([0, 0, 0, 1]).collect::<Vec<u8>>();
    let cases: Vec<(&str, Vec<u8>)> = vec![
        ("SIZE 2^31", vox_file(&[(b"SIZE", words(&[1 << 31, 1 << 31, 1 << 31])), (b"XYZI", one_voxel)])),
        ("XYZI claiming 2^31 voxels", vox_file(&[(b"SIZE", words(&[8, 8, 8])), (b"XYZI", words(&[1 << 31, 0, 0]))])),
        ("nGRP claiming 2^30 children", vox_file(&[(b"nGRP", words(&[0, 0, 1 << 30, 1, 2]))])),
        ("dictionary claiming 2^31 entries", vox_file(&[(b"MATL", words(&[1, 1 << 31, 4, 0]))])),
    ];
    for (name, bytes) in cases {
        let peak = peak_while_failing(&bytes);
        assert!(peak < 64 * 1024, "{name}: peak heap growth {peak} bytes");
    }
}
