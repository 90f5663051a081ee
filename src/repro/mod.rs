//! Reproductions of the theses' tables.
//!
//! - [`registry`]: every table of every thesis (title as printed, seed lines,
//!   status, scenes), the measurement groups that run the experiments and the
//!   render functions that make tables of their raw measurements;
//! - [`run`]: plans a run (tables, scenes, protocol, frames), estimates its
//!   time and executes it into [`results::Results`], the raw measurements that
//!   shards write and `tables merge` reads;
//! - [`table`]: a reproduced table with verdicts against the thesis'
//!   tolerances ([`compare`]), as markdown, text and CSV;
//! - [`baseline`]: the committed record of which cells agree, for regression tests;
//! - one module per thesis: `fabianowski2011` (seed 000), `engelhardt2013`
//!   (001), `zeidan2011` (002), `lin2017` (003), `purcell2003` (004).

pub mod baseline;
pub mod compare;
pub mod engelhardt2013;
pub mod fabianowski2011;
pub mod lin2017;
pub mod protocol;
pub mod purcell2003;
pub mod registry;
pub mod results;
pub mod run;
pub mod table;
pub mod zeidan2011;

/// The commit this warplight was built from (`unknown` outside a git checkout).
pub const COMMIT: &str = match option_env!("WARPLIGHT_COMMIT") {
    Some(c) => c,
    None => "unknown",
};
