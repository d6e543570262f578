//! The command line's allocator: the system's own, tuned as glibc's `GLIBC_TUNABLES` would tune
//! it for large working sets (heaps grown in large steps, kept when freed, backed by transparent
//! huge pages).
//!
//! Why: a `slice` of a 963k-triangle scan lives on large short-lived buffers (vertices, triangles,
//! the incidence table: 70 MB in all). Untuned, glibc's malloc maps each of them afresh and
//! unmaps it when freed, so every 4 KiB page of every buffer faults on its first touch: 17,600
//! faults a run, a fifth of the process's CPU on a virtual machine. Tuned, the same run takes
//! about 1,800 faults and 18% less CPU, and `reconstruct` is unchanged (docs/performance.md).
//! mimalloc and jemalloc (with huge pages) gave `slice` as much but made `reconstruct` 5-6%
//! slower and 60-80 MiB larger at its peak; one arena for all threads made it 8% slower.
//!
//! glibc's own switch for huge pages (`glibc.malloc.hugetlb=1`) is read from the environment
//! before `main`, so this does by hand what it does: memory malloc takes from the kernel is
//! advised `MADV_HUGEPAGE` (the heap's growth, a thread arena's heap, a block mapped on its own),
//! after the allocation that needed it. `main.rs` uses this only with glibc on Linux; elsewhere
//! the command line keeps the system allocator. Huge pages are advice: where the kernel's
//! `transparent_hugepage` mode is `never`, nothing changes.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, advising huge pages as glibc's `hugetlb=1` tunable would.
pub struct Allocator;

/// A transparent huge page on x86-64 and arm64 Linux (the PMD size with 4 KiB base pages).
const HUGE_PAGE: usize = 2 << 20;
/// Blocks up to this size come from the heap rather than a mapping of their own: glibc's upper
/// bound for its sliding threshold on 64-bit (`DEFAULT_MMAP_THRESHOLD_MAX`), fixed so that a
/// freed buffer is reused rather than unmapped.
const MMAP_THRESHOLD: usize = 32 << 20;
/// Free memory at the heap's top kept rather than returned: a large scan's working set.
const TRIM_THRESHOLD: usize = 256 << 20;
/// The heap grows by this much beyond each request: fewer, larger steps, each of whole huge
/// pages.
const TOP_PAD: usize = 64 << 20;

/// The base page size: smaller blocks are not advised.
const PAGE: usize = 4 << 10;
/// A chunk's size word: the chunk is a mapping of its own (glibc's malloc.c).
const IS_MMAPPED: usize = 0x2;
/// A chunk's size word: the chunk lies in a thread arena's heap (glibc's malloc.c).
const NON_MAIN_ARENA: usize = 0x4;
/// A thread arena's heap: reserved whole, aligned to its size (glibc's `HEAP_MAX_SIZE` on
/// 64-bit, twice `DEFAULT_MMAP_THRESHOLD_MAX`; its `free` finds a chunk's heap the same way).
const THREAD_HEAP: usize = 64 << 20;
/// Thread heaps advised so far: more than enough for one arena a thread on a small machine.
static THREAD_HEAPS_ADVISED: [AtomicUsize; 32] = [const { AtomicUsize::new(0) }; 32];

/// The end of the heap's part already advised (0 before `configure`: nothing is advised).
static ADVISED_TO: AtomicUsize = AtomicUsize::new(0);

/// Sets malloc's parameters; call first thing in `main`, before any thread starts (`mallopt`
/// is not meant to race allocations).
pub fn configure() {
    let parameters = [
        (libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD),
        (libc::M_TRIM_THRESHOLD, TRIM_THRESHOLD),
        (libc::M_TOP_PAD, TOP_PAD),
    ];
    for (parameter, value) in parameters {
        // SAFETY: mallopt only sets a parameter of malloc's. A refused value (it returns 0)
        // leaves glibc's default, which is merely slower.
        unsafe { libc::mallopt(parameter, value as libc::c_int) };
    }
    // SAFETY: sbrk(0) only reads the current end of the heap.
    let end = unsafe { libc::sbrk(0) } as usize;
    ADVISED_TO.store(end, Ordering::Relaxed);
}

/// After an allocation of `size` bytes at `ptr`, advises huge pages for the memory it came from,
/// as glibc's `hugetlb=1` does when it maps that memory: a block mapped on its own; a thread
/// arena's heap, whole, the first time a block comes from it; the main heap's growth since the
/// last look. Blocks under a page share their pages with others, and are left alone.
fn advise(ptr: *mut u8, size: usize) {
    let advised = ADVISED_TO.load(Ordering::Relaxed);
    if ptr.is_null() || advised == 0 || size < PAGE {
        return;
    }
    // SAFETY: every block glibc hands out is preceded by its chunk's size word, whose low bits
    // say where the chunk lives (malloc.c: IS_MMAPPED, NON_MAIN_ARENA).
    let size_word = unsafe { ptr.cast::<usize>().sub(1).read() };
    if size_word & IS_MMAPPED != 0 {
        advise_range(ptr as usize, ptr as usize + size);
    } else if size_word & NON_MAIN_ARENA != 0 {
        advise_thread_heap(ptr as usize & !(THREAD_HEAP - 1));
    } else {
        // SAFETY: sbrk(0) only reads the current end of the heap (no system call once known).
        let end = unsafe { libc::sbrk(0) } as usize;
        if end > advised
            && ADVISED_TO
                .compare_exchange(advised, end, Ordering::Relaxed, Ordering::Relaxed)
                .is_ok()
        {
            advise_range(advised, end);
        }
    }
}

/// Advises a thread arena's heap, whole, unless it was already (the first free slot of
/// `THREAD_HEAPS_ADVISED` takes it; with all slots taken, further heaps stay unadvised).
fn advise_thread_heap(base: usize) {
    for slot in &THREAD_HEAPS_ADVISED {
        match slot.compare_exchange(0, base, Ordering::Relaxed, Ordering::Relaxed) {
            Ok(_) => return advise_range(base, base + THREAD_HEAP),
            Err(taken) if taken == base => return,
            Err(_) => {}
        }
    }
}

/// Advises huge pages for the whole huge pages inside `[start, end)`.
fn advise_range(start: usize, end: usize) {
    let start = start.next_multiple_of(HUGE_PAGE);
    let end = end / HUGE_PAGE * HUGE_PAGE;
    if end > start {
        // SAFETY: the range is memory the allocator owns (the heap, or a block it just mapped);
        // MADV_HUGEPAGE changes how the kernel backs it, never its contents. A failure is
        // ignored: it is advice.
        unsafe { libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE) };
    }
}

// SAFETY: every call is passed to `System` unchanged; the advice only follows it and never
// touches a block's contents (a zeroed block is cleared in full before it is returned).
unsafe impl GlobalAlloc for Allocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract for this method, passed on to `System` unchanged.
        let ptr = unsafe { System.alloc(layout) };
        advise(ptr, layout.size());
        ptr
    }

    /// A heap block is cleared after the advice: glibc clears heap memory it hands out zeroed,
    /// which would fault it in small pages before the heap's growth is advised. A block mapped
    /// on its own comes zeroed from the kernel, untouched.
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.size() >= MMAP_THRESHOLD {
            // SAFETY: the caller's contract for this method, passed on to `System` unchanged.
            let ptr = unsafe { System.alloc_zeroed(layout) };
            advise(ptr, layout.size());
            return ptr;
        }
        // SAFETY: the caller's contract for this method, passed on to `System` unchanged.
        let ptr = unsafe { System.alloc(layout) };
        advise(ptr, layout.size());
        if !ptr.is_null() {
            // SAFETY: `ptr` is a fresh block of `layout.size()` bytes.
            unsafe { ptr.write_bytes(0, layout.size()) };
        }
        ptr
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: the caller's contract for this method, passed on to `System` unchanged.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: the caller's contract for this method, passed on to `System` unchanged.
        let new = unsafe { System.realloc(ptr, layout, new_size) };
        advise(new, new_size);
        new
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Blocks of every kind (small, heap, thread heap, mapped) hold what is written to them,
    /// come zeroed when asked even where freed dirty memory is reused, and keep their contents
    /// through realloc.
    #[test]
    fn blocks_are_zeroed_and_kept() {
        configure();
        let sizes = [24, PAGE, 3 << 20, MMAP_THRESHOLD + 4096];
        let check = move || {
            for size in sizes {
                let layout = Layout::from_size_align(size, 16).unwrap();
                // SAFETY: non-zero layouts; every block is freed once with its own layout.
                unsafe {
                    let dirty = Allocator.alloc(layout);
                    assert!(!dirty.is_null());
                    dirty.write_bytes(0xA5, size);
                    Allocator.dealloc(dirty, layout);
                    let zeroed = Allocator.alloc_zeroed(layout);
                    assert!(!zeroed.is_null());
                    assert!((0..size).all(|i| *zeroed.add(i) == 0), "{size} bytes not zeroed");
                    zeroed.write_bytes(0x5A, size);
                    let grown = Allocator.realloc(zeroed, layout, 2 * size);
                    assert!(!grown.is_null());
                    assert!((0..size).all(|i| *grown.add(i) == 0x5A), "{size} bytes not kept");
                    Allocator.dealloc(grown, Layout::from_size_align(2 * size, 16).unwrap());
                }
            }
        };
        check();
        std::thread::spawn(check).join().unwrap();
    }
}
