//! The commands around the renderer: the command line (its grammar in `args`,
//! the commands carried out in `cli`), `explain`, `accuracy`,
//! `bench` and its yardstick, `chart`, `diff`, the book's figures and diagrams, and
//! `generate`.

pub mod accuracy;
pub mod args;
pub mod bench;
pub mod chart;
pub mod cli;
pub mod compare;
pub mod diagrams;
pub mod explain;
pub mod figures;
pub mod generate;
pub mod json;
pub mod serve;
pub mod yardstick;
