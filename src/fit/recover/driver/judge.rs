//! Judging a fitted recovery level: whether it is dropped for its parent,
//! has gone wrong (left the box, lost the boundary), met the tolerance, or
//! should be refined (the driver counts where: `off`).

use crate::error::Result;
use crate::fit::levels::{Verdict, fitted_worse};
use crate::math::Real;
use crate::mesh::PolyMesh;

use super::VolumeFit;

impl VolumeFit<'_> {
    /// The verdict on the level just fitted (the last of `self.levels`),
    /// whose control mesh is `mesh`; `off` counts each face's samples off
    /// the boundary (what adaptive refinement splits) and `local` tells
    /// whether the level holds [`local_misses`].
    pub(super) fn judge(
        &mut self,
        mesh: &mut PolyMesh,
        off: Vec<usize>,
        local: bool,
    ) -> Result<Verdict> {
        let (params, levels, coarser) = (self.params, &self.levels, &self.coarser);
        let last = levels.last().expect("the level just fitted");
        let (level, offsets, unresolved, outside_box, unmatched, search, samples) = (
            last.level,
            &last.offsets,
            last.unresolved,
            last.outside_box,
            last.unmatched,
            last.search_voxels,
            last.samples,
        );
        // A finer level that follows the image worse than its parent on
        // every count (a thin structure can pull the finer surface's
        // springs across itself) is dropped and the parent returned.
        if let ([.., before, last], Some(parent)) = (levels.as_slice(), &coarser)
            && fitted_worse(
                (last.offsets.rms, last.offsets.p95),
                (before.offsets.rms, before.offsets.p95),
            )
            && last.unresolved >= before.unresolved
        {
            let reason = format!(
                "level {level} followed the image worse than level {} (RMS offset {:.3} > {:.3} voxels, {:.1} % unresolved): level {} returned",
                level - 1,
                last.offsets.rms,
                before.offsets.rms,
                100.0 * last.unresolved,
                level - 1
            );
            *mesh = parent.clone();
            self.dropped = true;
            return Ok(Verdict::Stop(false, reason));
        }
        if outside_box > 0.0 {
            return Ok(Verdict::Stop(
                false,
                format!(
                    "the surface left the volume's box at level {level}: {:.0} of its {} samples lie more than 1 voxel outside",
                    outside_box * samples as Real,
                    samples
                ),
            ));
        }
        if unresolved > params.max_unresolved {
            return Ok(Verdict::Stop(
                false,
                format!(
                    "{:.1} % of the surface found no boundary within ±{search:.1} voxels at level {level} (more than {:.0} %): finer levels would not find it",
                    100.0 * unresolved,
                    100.0 * params.max_unresolved
                ),
            ));
        }
        let met = (offsets.p95 <= params.tolerance_voxels
            && !local
            && unresolved < 0.01
            && unmatched <= params.max_unmatched)
            .then(|| format!("tolerance met at level {level}"));
        // The gain counts once the surface has found its boundary.
        let gain = match levels.as_slice() {
            [.., before, last] if last.unresolved < 0.01 => {
                Some((last.offsets.rms, before.offsets.rms))
            }
            _ => None,
        };
        self.off = off;
        Ok(Verdict::Judge {
            met,
            gain,
            measure: "RMS offset".into(),
        })
    }
}

/// Offsets beyond this many tolerances are a local miss.
pub(super) const LOCAL_MISS: Real = 1.2;

/// At most this share of the samples for [`local_misses`].
const LOCAL_MISS_SHARE: Real = 0.001;

/// Whether the offsets `t` (voxels) hold a few local misses: samples off
/// the boundary by more than [`LOCAL_MISS`] × `tolerance`, but at most
/// [`LOCAL_MISS_SHARE`] of them. The 95th percentile cannot see them: they
/// are a tip or an edge the level's cage is too coarse to reach (the
/// anvil's horn, 0.007 % of its samples at 0.87 voxel, while its 95th
/// percentile is 0.17), and splitting the few faces they lie on is cheap,
/// so the level is refined there. Many such samples are a surface rough
/// everywhere at this resolution (the MNI brain's sulci: 2.5 % beyond 0.6
/// voxel at level 0), whose faces would all be split: the 95th percentile
/// alone judges it. Chosen on the recovery bench's anvil, spot, bracket and
/// the MNI T1 brain (`benches/compare/RESULTS.md`).
pub(super) fn local_misses(t: &[Real], tolerance: Real) -> bool {
    let limit = LOCAL_MISS * tolerance;
    let misses = t.iter().filter(|&&x| x > limit).count();
    misses > 0 && misses as Real <= LOCAL_MISS_SHARE * t.len() as Real
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A few samples beyond 1.2 × the tolerance (a tip) refine; none, or a
    /// share above 0.1 % (a surface rough everywhere), do not.
    #[test]
    fn local_misses_are_a_few_samples_beyond_the_tolerance() {
        let mut t = vec![0.2; 10_000];
        assert!(!local_misses(&t, 0.5));
        t[17] = 0.87;
        assert!(local_misses(&t, 0.5));
        t[18] = 0.59; // within 1.2 × 0.5
        assert!(local_misses(&t, 0.5));
        for x in t.iter_mut().take(11) {
            *x = 0.8;
        }
        assert!(!local_misses(&t, 0.5), "12 of 10,000 is more than 0.1 %");
        assert!(!local_misses(&[], 0.5));
    }
}
