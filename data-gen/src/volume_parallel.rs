//! Splitting a volume into bands of y rows so that threads can fill disjoint
//! parts of it with safe `&mut` slices (std scoped threads; output does not
//! depend on the number of threads).

use std::ops::Range;

/// Number of worker threads: the machine's parallelism, at most `work` (≥ 1).
pub fn thread_count(work: usize) -> usize {
    let n = std::thread::available_parallelism().map_or(1, |n| n.get());
    n.min(work).max(1)
}

/// One band: rows `rows` of every z slice, as one slice per z
/// (`slabs[k]` holds rows `rows` of slice `k`, x fastest).
pub struct Band<'a> {
    /// The y rows of this band.
    pub rows: Range<usize>,
    /// One `&mut` run of `rows.len() × nx` values per z slice.
    pub slabs: Vec<&'a mut [f32]>,
}

/// Cuts `data` (`nx × ny × nz`, x fastest) into `n` bands of consecutive y rows.
pub fn row_bands(data: &mut [f32], dims: [usize; 3], n: usize) -> Vec<Band<'_>> {
    let [nx, ny, _] = dims;
    let n = n.clamp(1, ny.max(1));
    let bounds: Vec<usize> = (0..=n).map(|b| ny * b / n).collect();
    let mut bands: Vec<Band> = (0..n)
        .map(|b| Band {
            rows: bounds[b]..bounds[b + 1],
            slabs: Vec::new(),
        })
        .collect();
    for slab in data.chunks_mut(nx * ny) {
        let mut rest = slab;
        for band in bands.iter_mut() {
            let (head, tail) = rest.split_at_mut(band.rows.len() * nx);
            band.slabs.push(head);
            rest = tail;
        }
    }
    bands
}

/// Runs `work` on every band of `data` in parallel.
pub fn for_each_band(data: &mut [f32], dims: [usize; 3], work: impl Fn(Band<'_>) + Sync) {
    let bands = row_bands(data, dims, thread_count(dims[1]));
    std::thread::scope(|scope| {
        for band in bands {
            let work = &work;
            scope.spawn(move || work(band));
        }
    });
}

/// Runs `work(k, slice)` on every z slice of `data` in parallel.
pub fn for_each_slice(data: &mut [f32], dims: [usize; 3], work: impl Fn(usize, &mut [f32]) + Sync) {
    let per_slice = dims[0] * dims[1];
    let threads = thread_count(dims[2]);
    let slices_per_thread = dims[2].div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        for (t, chunk) in data.chunks_mut(per_slice * slices_per_thread).enumerate() {
            let work = &work;
            scope.spawn(move || {
                for (s, slice) in chunk.chunks_mut(per_slice).enumerate() {
                    work(t * slices_per_thread + s, slice);
                }
            });
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_cover_every_voxel_once() {
        let dims = [3, 7, 4];
        let mut data = vec![0.0f32; 3 * 7 * 4];
        for_each_band(&mut data, dims, |band| {
            for (k, slab) in band.slabs.into_iter().enumerate() {
                for (r, row) in slab.chunks_mut(dims[0]).enumerate() {
                    let j = band.rows.start + r;
                    for (i, v) in row.iter_mut().enumerate() {
                        *v += (i + dims[0] * (j + dims[1] * k)) as f32;
                    }
                }
            }
        });
        for (idx, v) in data.iter().enumerate() {
            assert_eq!(*v, idx as f32);
        }
    }
}
