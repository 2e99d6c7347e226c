//! What colour a hit point gets: one file for each stage that changes a colour.

pub mod blinn_phong;
pub mod reflection;
pub mod shadow;
