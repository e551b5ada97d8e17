//! The `subdyn` binary's global allocator: the system's, except that an
//! allocation the system refuses ends the run with one line and exit code 1
//! (after removing the run's temporary files), where Rust's default prints
//! `memory allocation of N bytes failed` and aborts (a second line from the
//! shell, a core dump, and temporary files left behind).
//!
//! The memory budget ([`crate::memory`]) refuses the large buffers it can
//! estimate before they are allocated; this is the last line for the rest
//! (a budget set above what the machine has, an address-space limit).
//! Fallible reservations that handle their own failure go through
//! [`try_reserve_exact`], which still gets the error.
//!
//! ```no_run
//! #[global_allocator]
//! static ALLOCATOR: subdyn::allocator::OneLineOutOfMemory = subdyn::allocator::OneLineOutOfMemory;
//! ```

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::collections::TryReserveError;
use std::io::Write;

thread_local! {
    /// Set while this thread makes a reservation whose failure it handles.
    static FALLIBLE: Cell<bool> = const { Cell::new(false) };
}

/// The system allocator with a one-line exit when it refuses (see the
/// module's docs).
pub struct OneLineOutOfMemory;

// SAFETY: every call is forwarded to `System` with the same arguments; the
// only addition is what happens when it returns null.
unsafe impl GlobalAlloc for OneLineOutOfMemory {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: the caller's contract is `System.alloc`'s.
        checked(unsafe { System.alloc(layout) }, layout.size())
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as above.
        checked(unsafe { System.alloc_zeroed(layout) }, layout.size())
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: as above.
        checked(unsafe { System.realloc(ptr, layout, new_size) }, new_size)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: as above.
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// `ptr`, unless it is null outside a fallible reservation: then the run ends.
fn checked(ptr: *mut u8, bytes: usize) -> *mut u8 {
    if ptr.is_null() && !FALLIBLE.with(Cell::get) {
        out_of_memory(bytes);
    }
    ptr
}

/// Removes the run's temporary files, prints one line and exits with 1.
/// Formats into a stack buffer: the refused allocation was large, but the
/// line itself must not need the heap.
fn out_of_memory(bytes: usize) -> ! {
    crate::io::remove_temporary_files();
    let mut line = [0u8; 256];
    let mut cursor = std::io::Cursor::new(&mut line[..]);
    let _ = writeln!(
        cursor,
        "subdyn: error: out of memory: the system refused {:.1} MB; nothing was written (a --max-memory below what this machine gives makes such work refused before it starts)",
        bytes as f64 / 1e6
    );
    let n = cursor.position() as usize;
    // SAFETY: write(2) of `n` initialised bytes to standard error, then
    // _exit(2), which ends the process without running anything else.
    unsafe {
        libc::write(2, line.as_ptr().cast(), n);
        libc::_exit(1)
    }
}

/// `v.try_reserve_exact(additional)`, whose failure comes back as the error
/// under [`OneLineOutOfMemory`] too.
pub fn try_reserve_exact<T>(v: &mut Vec<T>, additional: usize) -> Result<(), TryReserveError> {
    FALLIBLE.with(|f| f.set(true));
    let result = v.try_reserve_exact(additional);
    FALLIBLE.with(|f| f.set(false));
    result
}
