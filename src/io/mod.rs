//! Files in and out: scene files, the PNG and EXR buffers, the page and the
//! contact sheet. They read the book's types and never change what is rendered.

pub mod contact;
pub mod generated;
pub mod output;
pub mod page;
pub mod scene_file;
