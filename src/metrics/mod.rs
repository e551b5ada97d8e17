//! Distances between geometry: point-to-triangle-mesh distances with a BVH,
//! one-sided and symmetric statistics, Chamfer and Hausdorff distances.
