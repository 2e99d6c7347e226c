//! # raystep: ray tracing, one step at a time
//!
//! raystep follows the tutorial "Ray Tracing From Scratch in Python" (Omar Aflak,
//! 2020) one stage at a time. The whole pipeline, for every pixel of the image:
//!
//! ```text
//! scene file ──► Scene ──► for each pixel:
//!     camera + screen rectangle ──► primary ray            (camera, ray)     stage `rays`
//!     nearest object along the ray ──► hit point, normal   (sphere, scene)   stage `intersection`
//!     anything between the hit point and the light?       (shade::shadow)   stage `shadow`
//!     ambient + diffuse + specular                          (shade::blinn_phong) stage `blinn-phong`
//!     bounce off the surface, add the weighted colour       (shade::reflection)  stage `reflection`
//!     the floor ("fake plane") takes part                   (plane)           stage `plane`
//! ──► colour clipped to [0, 1] and the first-hit record ──► buffers (aov) ──► PNG + EXR (output)
//! ```
//!
//! The modules below are grouped by the chapter that introduces them, each group
//! naming its chapter, so this file reads as a rough table of contents (the
//! pixel loop, `render`, and the buffers, `aov`, appear from chapters 2 and 3 on,
//! and are listed after the stages they run).
// One place only, with its reason: the packet loop's AVX build, declared
// `unsafe` for its target feature, and its call once the processor is found to
// have AVX (`Fast::packet_row`, fast/mod.rs).
#![deny(unsafe_code)]
#![warn(missing_docs)]

/// The 3-vector used for points, directions and colours (float64).
pub use glam::DVec3 as Vec3;

// Chapters 1 and 2: the scene, the camera and its rays.
pub mod camera;
pub mod ray;
pub mod scene;
// Chapter 9: the numbers the tracer computes in, float32 or float64.
pub mod real;
// Chapter 3: intersection.
pub mod sphere;
// Chapters 4-6: shadow, Blinn-Phong, reflection.
pub mod shade;
// Chapter 7: the plane.
pub mod plane;
// The switches, the book's tracer (the pixel loop) and the buffers it fills.
pub mod aov;
pub mod render;
pub mod stages;
// Chapter 10: samples, and finding the nearest hit without testing every object.
pub mod accel;
pub mod bvh;
pub mod samples;

// What serves the book, each part depending on the book and never the other way
// round: the fast engine, the one place that picks an engine, files in and out,
// the commands, and the errors and Ctrl-C they share.
pub mod engine;
pub mod error;
pub mod fast;
pub mod interrupt;
pub mod io;
pub mod tools;
