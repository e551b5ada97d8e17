//! A dense boolean voxel grid and the operations the occupancy cage needs:
//! dilation and erosion by the 3×3×3 cube, outside flood fill (6-connected,
//! from the grid border), cavity filling and the largest solid component.
//! Voxels outside the grid count as empty.

use std::collections::VecDeque;

/// The six face neighbours.
pub const FACE_NEIGHBOURS: [[isize; 3]; 6] = [
    [1, 0, 0],
    [-1, 0, 0],
    [0, 1, 0],
    [0, -1, 0],
    [0, 0, 1],
    [0, 0, -1],
];

/// `dims[0] × dims[1] × dims[2]` voxels, voxel `(i, j, k)` at `i + d0 (j + d1 k)`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VoxelGrid {
    /// Voxels along each axis.
    pub dims: [usize; 3],
    /// True for solid (occupied) voxels.
    pub solid: Vec<bool>,
}

impl VoxelGrid {
    /// An all-empty grid.
    pub fn new(dims: [usize; 3]) -> VoxelGrid {
        VoxelGrid {
            dims,
            solid: vec![false; dims[0] * dims[1] * dims[2]],
        }
    }

    /// Linear index of an in-grid voxel, `None` outside.
    pub fn index(&self, v: [isize; 3]) -> Option<usize> {
        let [d0, d1, d2] = self.dims;
        if v[0] < 0 || v[1] < 0 || v[2] < 0 {
            return None;
        }
        let (i, j, k) = (v[0] as usize, v[1] as usize, v[2] as usize);
        (i < d0 && j < d1 && k < d2).then(|| i + d0 * (j + d1 * k))
    }

    /// Coordinates of linear index `n`.
    pub fn coords(&self, n: usize) -> [isize; 3] {
        let [d0, d1, _] = self.dims;
        [
            (n % d0) as isize,
            ((n / d0) % d1) as isize,
            (n / (d0 * d1)) as isize,
        ]
    }

    /// Solid state of `v`; false outside the grid.
    pub fn get(&self, v: [isize; 3]) -> bool {
        self.index(v).is_some_and(|n| self.solid[n])
    }

    /// Number of solid voxels.
    pub fn count(&self) -> usize {
        self.solid.iter().filter(|&&s| s).count()
    }

    /// Dilation by the 3×3×3 cube: solid where any of the 27 voxels is solid.
    pub fn dilated(&self) -> VoxelGrid {
        self.morph(true)
    }

    /// Erosion by the 3×3×3 cube: solid where all 27 voxels are solid.
    pub fn eroded(&self) -> VoxelGrid {
        self.morph(false)
    }

    fn morph(&self, dilate: bool) -> VoxelGrid {
        let mut out = VoxelGrid::new(self.dims);
        for (n, o) in out.solid.iter_mut().enumerate() {
            let c = self.coords(n);
            let mut any = false;
            let mut all = true;
            for dk in -1..=1 {
                for dj in -1..=1 {
                    for di in -1..=1 {
                        let s = self.get([c[0] + di, c[1] + dj, c[2] + dk]);
                        any |= s;
                        all &= s;
                    }
                }
            }
            *o = if dilate { any } else { all };
        }
        out
    }

    /// Closing of the cavity-filled set by `k` cubes: dilate `k` times, make
    /// every voxel not reached from the border solid, erode `k` times. Closes
    /// gaps up to `2k` voxels wide in a shell; `k = 0` only fills the inside.
    pub fn closed_solid(&self, k: usize) -> VoxelGrid {
        let mut g = self.clone();
        for _ in 0..k {
            g = g.dilated();
        }
        g.fill_cavities();
        for _ in 0..k {
            g = g.eroded();
        }
        g
    }

    /// Empty voxels 6-connected to the grid border through empty voxels.
    pub fn outside(&self) -> Vec<bool> {
        let mut out = vec![false; self.solid.len()];
        let mut queue = VecDeque::new();
        let [d0, d1, d2] = self.dims;
        for (n, o) in out.iter_mut().enumerate() {
            let c = self.coords(n);
            let border = c[0] == 0
                || c[1] == 0
                || c[2] == 0
                || c[0] as usize == d0 - 1
                || c[1] as usize == d1 - 1
                || c[2] as usize == d2 - 1;
            if border && !self.solid[n] {
                *o = true;
                queue.push_back(n);
            }
        }
        while let Some(n) = queue.pop_front() {
            let c = self.coords(n);
            for d in FACE_NEIGHBOURS {
                if let Some(m) = self.index([c[0] + d[0], c[1] + d[1], c[2] + d[2]])
                    && !self.solid[m]
                    && !out[m]
                {
                    out[m] = true;
                    queue.push_back(m);
                }
            }
        }
        out
    }

    /// Makes every empty voxel not reached from the border solid; returns how many.
    pub fn fill_cavities(&mut self) -> usize {
        let outside = self.outside();
        let mut filled = 0;
        for (s, o) in self.solid.iter_mut().zip(&outside) {
            if !*s && !*o {
                *s = true;
                filled += 1;
            }
        }
        filled
    }

    /// Keeps only the largest 6-connected solid component; returns the number
    /// of other components removed.
    pub fn keep_largest_component(&mut self) -> usize {
        let mut label = vec![usize::MAX; self.solid.len()];
        let mut sizes = Vec::new();
        let mut queue = VecDeque::new();
        for start in 0..self.solid.len() {
            if !self.solid[start] || label[start] != usize::MAX {
                continue;
            }
            let id = sizes.len();
            label[start] = id;
            queue.push_back(start);
            let mut size = 0usize;
            while let Some(n) = queue.pop_front() {
                size += 1;
                let c = self.coords(n);
                for d in FACE_NEIGHBOURS {
                    if let Some(m) = self.index([c[0] + d[0], c[1] + d[1], c[2] + d[2]])
                        && self.solid[m]
                        && label[m] == usize::MAX
                    {
                        label[m] = id;
                        queue.push_back(m);
                    }
                }
            }
            sizes.push(size);
        }
        let Some(best) = (0..sizes.len()).max_by_key(|&i| (sizes[i], usize::MAX - i)) else {
            return 0;
        };
        for (s, l) in self.solid.iter_mut().zip(&label) {
            *s = *l == best;
        }
        sizes.len() - 1
    }
}
