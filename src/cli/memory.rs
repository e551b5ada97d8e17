//! Peak resident memory per stage, from Linux's `/proc/self/status`.
//!
//! `VmHWM` is the process's high-water mark of resident memory; writing `5`
//! to `/proc/self/clear_refs` (Linux ≥ 4.0) resets it to the current
//! resident size, so a reset before a stage and a read after it give that
//! stage's peak, whatever was allocated and freed inside it. The numbers
//! count every resident page (code, allocator slack, freed memory the
//! allocator keeps), so they are an upper bound on what the stage's data
//! needs. Elsewhere, or when `/proc` is unavailable, everything is `None`.

/// One `kB` field of `/proc/self/status` in bytes.
fn status_bytes(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Peak resident memory since the start or the last [`reset_peak`], bytes.
pub fn peak_rss() -> Option<u64> {
    status_bytes("VmHWM:")
}

/// Resident memory now, bytes.
pub fn current_rss() -> Option<u64> {
    status_bytes("VmRSS:")
}

/// Resets the peak to the current resident size; false if the kernel
/// does not allow it (then [`peak_rss`] keeps counting from the start).
pub fn reset_peak() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// The peak of `f`'s run in bytes (if measurable) and its result.
pub fn stage_peak<T>(f: impl FnOnce() -> T) -> (T, Option<u64>) {
    let reset = reset_peak();
    let out = f();
    (out, if reset { peak_rss() } else { None })
}

/// The peak resident memory of named stages against a volume's f32 size.
#[derive(Clone, Debug)]
pub struct StagePeaks {
    /// Bytes of the input volume as f32 samples.
    pub volume_bytes: u64,
    /// Stage names and their peaks in bytes (`None`: not measurable).
    pub stages: Vec<(&'static str, Option<u64>)>,
}

impl StagePeaks {
    /// The largest peak, if any stage was measured.
    pub fn max(&self) -> Option<u64> {
        self.stages.iter().filter_map(|s| s.1).max()
    }

    /// `bytes` as a multiple of the volume's f32 size.
    pub fn ratio(&self, bytes: u64) -> f64 {
        bytes as f64 / self.volume_bytes.max(1) as f64
    }

    /// One summary line, `peak memory: read 70 MB (1.0 ×), …`, ending in a
    /// newline; empty when nothing was measured.
    pub fn line(&self) -> String {
        let parts: Vec<String> = self
            .stages
            .iter()
            .filter_map(|(name, p)| {
                p.map(|p| format!("{name} {:.0} MB ({:.2} ×)", p as f64 / 1e6, self.ratio(p)))
            })
            .collect();
        if parts.is_empty() {
            return String::new();
        }
        format!(
            "peak memory: {} (× the volume's f32 size, {:.0} MB)\n",
            parts.join(", "),
            self.volume_bytes as f64 / 1e6
        )
    }

    /// `{"volume_f32_bytes": …, "stages": {name: bytes, …}, "max_ratio": …}`.
    pub fn json(&self) -> serde_json::Value {
        let stages: serde_json::Map<String, serde_json::Value> = self
            .stages
            .iter()
            .map(|(name, p)| (name.to_string(), serde_json::json!(p)))
            .collect();
        serde_json::json!({
            "volume_f32_bytes": self.volume_bytes,
            "stages_bytes": stages,
            "max_ratio": self.max().map(|m| self.ratio(m)),
        })
    }
}
