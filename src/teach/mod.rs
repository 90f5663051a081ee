//! Teaching views over the stepping API: the interactive terminal view of
//! `warplight step` ([`tui`]), its text log ([`log`]), and the HTML timeline
//! of `warplight trace` ([`trace`]). They share a replayable launch
//! ([`session`]), source-file lookup ([`sources`]) and the per-step notes on
//! divergence and reconvergence ([`track`]), each step's `printf` output
//! ([`printed`]), and which line of the user's source an instruction belongs
//! to ([`user_lines`]).

pub mod breakpoints;
pub mod log;
pub mod printed;
pub mod session;
pub mod sources;
pub mod trace;
pub mod track;
pub mod tui;
pub mod user_lines;
