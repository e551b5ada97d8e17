//! OpenEXR slices: one layer with one channel (or a channel named `Y` among
//! several), f32, f16 or u32 samples; rows top first, so row 0 is y = 0.

use std::path::{Path, PathBuf};

use ::exr::prelude::FlatSamples;

use super::decoded::{Decoded, Placement};
use super::slices::{Slice, name};
use crate::error::{Error, Result};

/// Decodes one EXR image into a slice.
pub(crate) fn exr_slice(path: &Path) -> Result<Slice> {
    use ::exr::prelude::traits::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| Error::parse(path, 0, format!("cannot decode the EXR: {e}")))?;
    let layer = &image.layer_data;
    let channels = &layer.channel_data.list;
    let channel = if channels.len() == 1 {
        &channels[0]
    } else {
        channels.iter().find(|c| c.name == *"Y").ok_or_else(|| {
            let names: Vec<String> = channels.iter().map(|c| c.name.to_string()).collect();
            Error::parse(
                path,
                0,
                format!(
                    "{} channels ({}) and none named Y: give single-channel EXR slices",
                    channels.len(),
                    names.join(", ")
                ),
            )
        })?
    };
    let (kind, samples): (&str, Vec<f32>) = match &channel.sample_data {
        FlatSamples::F32(v) => ("32-bit float", v.clone()),
        FlatSamples::F16(v) => ("16-bit float", v.iter().map(|x| x.to_f32()).collect()),
        FlatSamples::U32(v) => ("32-bit unsigned", v.iter().map(|&x| x as f32).collect()),
    };
    Ok(Slice {
        width: layer.size.0,
        height: layer.size.1,
        kind: kind.into(),
        samples,
        note: (channels.len() > 1).then(|| "EXR channel Y read, others ignored".to_string()),
    })
}

/// A single EXR file as a volume one slice thick.
pub(crate) fn read_exr_file(path: &Path) -> Result<Decoded> {
    super::slices::check_decoded(
        &format!("decoding {}", name(path)),
        super::slices::file_samples(path)?,
    )?;
    let s = exr_slice(path)?;
    let owned: PathBuf = path.to_path_buf();
    Ok(Decoded {
        dims: [s.width, s.height, 1],
        source: format!("EXR ({}), {}", s.kind, name(&owned)),
        notes: s.note.into_iter().collect(),
        data: s.samples,
        placement: Placement::Grid { spacing: None },
        physical: false,
    })
}
