//! `--threads` (or `RAYON_NUM_THREADS`): the size of the worker pool, bounded
//! by the machine.

/// Most worker threads per core that `--threads` accepts: oversubscribing a
/// core a few times can make sense (testing, sharing a machine), thousands
/// of threads only exhaust memory and the kernel's thread limit.
const THREADS_PER_CORE: usize = 4;

/// The cores of this machine (1 if unknown).
fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// The most threads accepted: [`THREADS_PER_CORE`] × the cores.
pub fn max_threads() -> usize {
    THREADS_PER_CORE * cores()
}

/// Starts the global worker pool with `threads` (from `--threads`), else
/// `RAYON_NUM_THREADS`, else one per core; a count of 0 or over
/// [`max_threads`], or an unreadable environment value, is an error.
pub fn start_pool(threads: Option<usize>) -> anyhow::Result<()> {
    let (count, source) = match threads {
        Some(t) => (t, "--threads"),
        None => match std::env::var("RAYON_NUM_THREADS") {
            Ok(text) => (
                text.trim().parse::<usize>().map_err(|_| {
                    anyhow::anyhow!("RAYON_NUM_THREADS={text:?} is not a whole number of threads")
                })?,
                "RAYON_NUM_THREADS",
            ),
            Err(_) => return Ok(()),
        },
    };
    let max = max_threads();
    if count == 0 || count > max {
        anyhow::bail!(
            "{source} {count}: expected 1 to {max} threads ({THREADS_PER_CORE} per core on this \
             machine's {} cores)",
            cores()
        );
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(count)
        .build_global()
        .map_err(|e| anyhow::anyhow!("cannot start {count} threads: {e}"))
}
