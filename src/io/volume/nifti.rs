//! NIfTI-1 single-file volumes, `.nii` and `.nii.gz` (gzip is recognised by
//! its magic bytes, whatever the name). The header is parsed by
//! [`nifti_header`](super::nifti_header); the voxels are streamed from the
//! (decompressing) reader straight into f32, so a `.nii.gz` is never held
//! uncompressed in full.

use std::io::{BufReader, Read};
use std::path::Path;

use flate2::read::MultiGzDecoder;

use super::decoded::{Decoded, Placement};
use super::nifti_header::{NIFTI1_HEADER_BYTES, nifti_header};
use super::samples::{read_samples, skip_bytes};
use crate::error::{Error, Result};

/// Inflates the rest of a `.nii.gz` (the other volumes of a 4D file, at
/// most what the header declares) so the gzip trailer's CRC and length are
/// checked: a damaged or cut stream is an error, not a volume.
fn check_gzip_end(
    reader: &mut dyn Read,
    header: &super::nifti_header::NiftiHeader,
    count: usize,
    path: &Path,
) -> Result<()> {
    let rest = (header.volumes.saturating_sub(1) as u64)
        .saturating_mul(count as u64)
        .saturating_mul(header.datatype.size() as u64)
        // A few bytes of padding or extensions after the data.
        .saturating_add(1 << 16);
    let drained = std::io::copy(
        &mut reader.take(rest.saturating_add(1)),
        &mut std::io::sink(),
    )
    .map_err(|e| Error::parse(path, 0, format!("the gzip stream after the voxels: {e}")))?;
    if drained > rest {
        return Err(Error::parse(
            path,
            0,
            format!(
                "more data after the voxels than the header's {} volumes hold",
                header.volumes
            ),
        ));
    }
    Ok(())
}

/// Reads the first 3D volume of a NIfTI-1 file, in physical units
/// (`scl_slope`, `scl_inter` applied) and world coordinates (see
/// [`nifti_header`](super::nifti_header) for the map).
pub(crate) fn read_nifti(path: &Path) -> Result<Decoded> {
    let file = crate::io::open_regular(path)?;
    let mut buffered = BufReader::with_capacity(1 << 16, file);
    let mut magic = [0u8; 2];
    let gzip = {
        use std::io::BufRead;
        let head = buffered.fill_buf().map_err(|e| Error::io(path, e))?;
        if head.len() >= 2 {
            magic.copy_from_slice(&head[..2]);
        }
        magic == [0x1f, 0x8b]
    };
    let mut reader: Box<dyn Read> = if gzip {
        Box::new(BufReader::with_capacity(
            1 << 16,
            MultiGzDecoder::new(buffered),
        ))
    } else {
        Box::new(buffered)
    };

    let mut head = Vec::with_capacity(NIFTI1_HEADER_BYTES);
    (&mut reader)
        .take(NIFTI1_HEADER_BYTES as u64)
        .read_to_end(&mut head)
        .map_err(|e| Error::parse(path, 0, format!("reading the header: {e}")))?;
    let header = nifti_header(&head, path)?;
    let gap = header.vox_offset - NIFTI1_HEADER_BYTES as u64;
    if !skip_bytes(&mut reader, gap, path)? {
        return Err(Error::parse(
            path,
            0,
            format!(
                "vox_offset {} is beyond the end of the file",
                header.vox_offset
            ),
        ));
    }
    let count = header.dims.iter().product();
    let mut data = read_samples(&mut reader, count, header.datatype, header.big_endian, path)?;
    if gzip {
        check_gzip_end(&mut reader, &header, count, path)?;
    }
    if let Some((slope, inter)) = header.scaling {
        for v in data.iter_mut() {
            *v = (slope * f64::from(*v) + inter) as f32;
        }
    }
    let mut notes = vec![format!("voxel-to-world map from the {}", header.method)];
    notes.extend(header.notes);
    if header.volumes > 1 {
        notes.push(format!(
            "the file holds {} volumes; only the first is read",
            header.volumes
        ));
    }
    Ok(Decoded {
        dims: header.dims,
        data,
        placement: Placement::Affine {
            linear: header.linear,
            origin: header.origin,
        },
        source: format!(
            "NIfTI-1{}, {}, {}-endian",
            if gzip { " (gzip)" } else { "" },
            header.datatype.name(),
            if header.big_endian { "big" } else { "little" }
        ),
        notes,
        physical: true,
    })
}
