//! SIGINT, SIGTERM and SIGHUP end a run without leaving temporary files.
//!
//! The handler itself only writes the signal's number to a pipe (`write` is
//! async-signal-safe); a watcher thread reads it, removes every temporary
//! file of the run (`subdyn::io::remove_temporary_files`), prints one line
//! and exits with 128 + the signal's number, as a shell does.

use std::sync::atomic::{AtomicI32, Ordering};

/// The pipe's write end, for the handler (-1 before [`install`]).
static PIPE: AtomicI32 = AtomicI32::new(-1);

/// The signals handled.
const SIGNALS: [(libc::c_int, &str); 3] = [
    (libc::SIGINT, "SIGINT"),
    (libc::SIGTERM, "SIGTERM"),
    (libc::SIGHUP, "SIGHUP"),
];

extern "C" fn on_signal(sig: libc::c_int) {
    let byte = sig as u8;
    // SAFETY: write(2) on a pipe is async-signal-safe; a failure is ignored.
    unsafe {
        libc::write(PIPE.load(Ordering::Relaxed), (&byte as *const u8).cast(), 1);
    }
}

/// Installs the handlers and starts the watcher; without a pipe or a thread
/// the signals keep their default action (the run still stops, and only
/// the temporary files of an interrupted write may stay behind).
pub fn install() {
    let mut fds = [0 as libc::c_int; 2];
    // SAFETY: pipe(2) fills the two descriptors of a valid array.
    if unsafe { libc::pipe(fds.as_mut_ptr()) } != 0 {
        return;
    }
    let read_end = fds[0];
    let watcher = std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            let mut byte = 0u8;
            // SAFETY: read(2) into one valid byte.
            let n = unsafe { libc::read(read_end, (&mut byte as *mut u8).cast(), 1) };
            if n != 1 {
                return;
            }
            subdyn::io::remove_temporary_files();
            let sig = libc::c_int::from(byte);
            let name = SIGNALS
                .iter()
                .find(|(s, _)| *s == sig)
                .map_or("a signal", |(_, n)| n);
            eprintln!("subdyn: error: stopped by {name}; no output was written");
            // SAFETY: _exit(2) ends the process at once.
            unsafe { libc::_exit(128 + sig) }
        });
    if watcher.is_err() {
        return;
    }
    PIPE.store(fds[1], Ordering::Relaxed);
    for (sig, _) in SIGNALS {
        // SAFETY: a zeroed sigaction with a plain handler is valid; the
        // handler only calls write(2).
        unsafe {
            let mut action: libc::sigaction = std::mem::zeroed();
            action.sa_sigaction = on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t;
            action.sa_flags = libc::SA_RESTART;
            libc::sigemptyset(&mut action.sa_mask);
            libc::sigaction(sig, &action, std::ptr::null_mut());
        }
    }
}
