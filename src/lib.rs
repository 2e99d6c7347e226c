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
//! The modules below are listed in the order the book introduces them, so this
//! file reads as its table of contents.
// One place only, with its reason: the call of the packet loop's AVX build once
// the processor is found to have AVX (`Fast::packet_row`, fast.rs).
#![deny(unsafe_code)]
#![warn(missing_docs)]

/// The 3-vector used for points, directions and colours (float64).
pub use glam::DVec3 as Vec3;

// Chapter 1: setting the scene.
pub mod camera;
pub mod scene;
pub mod scene_file;
// Chapter 2: rays.
pub mod ray;
pub mod real;
// Chapter 3: intersection.
pub mod sphere;
// Chapters 4-6: shadow, Blinn-Phong, reflection.
pub mod shade;
// Chapter 7: the plane.
pub mod plane;
// The switches, the pixel loop and what it writes.
pub mod aov;
pub mod contact;
pub mod output;
pub mod page;
pub mod render;
pub mod samples;
pub mod stages;
// Speed: skipping tests that cannot succeed, and four rays at once.
pub mod accel;
pub mod bvh;
pub mod engine;
pub mod fast;
pub mod lanes;
pub mod packet;
// The command line, its errors, and the tools around the renderer.
pub mod accuracy;
pub mod bench;
pub mod chart;
pub mod cli;
pub mod compare;
pub mod error;
pub mod explain;
pub mod figures;
pub mod generate;
pub mod interrupt;
pub mod yardstick;
