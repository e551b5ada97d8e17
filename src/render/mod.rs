//! A small software rasteriser for looking at results: z-buffer, Lambert
//! shading, point splats, distance colour maps with a legend.
