//! Limit surface evaluation.
