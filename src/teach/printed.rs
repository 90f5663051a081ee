//! The `printf` output of a stepped launch, step by step: each warp
//! instruction that calls `printf` hands out its lanes' records (in lane
//! order) as it is issued, so the log, the terminal view and the HTML trace
//! show each line at the step that printed it. The whole launch's output, in
//! `crate::sim::printf`'s order (CTA, warp, call, lane), stays available after
//! the stepping ([`super::session::Session::printf_output`]).

use std::cell::RefCell;

use crate::sim::Device;
use crate::sim::printf::PrintfRecord;

/// The `printf` output of the launch being stepped, taken step by step.
pub struct Printed<'a> {
    dev: &'a Device,
    /// Everything taken so far (for the whole launch's output at the end).
    taken: RefCell<Vec<PrintfRecord>>,
}

impl<'a> Printed<'a> {
    /// The output of `dev`'s launch from now on (earlier output must have been
    /// taken from the device already).
    pub(super) fn new(dev: &'a Device) -> Printed<'a> {
        Printed { dev, taken: RefCell::new(Vec::new()) }
    }

    /// The records printed since the last call: after a step, that step's
    /// output (one warp's call, by lane); empty when it printed nothing.
    pub fn take(&self) -> Vec<PrintfRecord> {
        let recs = self.dev.take_printf();
        if !recs.is_empty() {
            self.taken.borrow_mut().extend(recs.iter().cloned());
        }
        recs
    }

    /// All output of the stepping, taken or not, in the order of
    /// `crate::sim::printf` (launch, CTA, warp, call, lane).
    pub(super) fn finish(self) -> Vec<PrintfRecord> {
        let mut all = self.taken.into_inner();
        all.extend(self.dev.take_printf());
        all.sort_by_key(|r| (r.launch, r.cta_linear, r.warp, r.seq, r.lane));
        all
    }
}

/// The lines of one lane's output, without their newlines (a text without a
/// final newline still makes a line; an empty text none).
pub fn lines(rec: &PrintfRecord) -> impl Iterator<Item = &str> {
    rec.text.strip_suffix('\n').unwrap_or(&rec.text).split('\n').filter(move |_| !rec.text.is_empty())
}

/// The lines of one step's output as the log and the terminal view show
/// them: `cta C warp W lane L> TEXT` (C the CTA's linear index).
pub fn labelled(recs: &[PrintfRecord]) -> Vec<String> {
    recs.iter()
        .flat_map(|r| lines(r).map(move |l| format!("cta {} warp {} lane {:>2}> {l}", r.cta_linear, r.warp, r.lane)))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(lane: u32, text: &str) -> PrintfRecord {
        PrintfRecord { launch: 0, cta_linear: 1, cta: [1, 0, 0], warp: 2, seq: 0, lane, text: text.into() }
    }

    #[test]
    fn each_line_of_each_lane_is_labelled() {
        let recs = [rec(0, "a\n"), rec(3, "b\nc\n"), rec(4, "no newline"), rec(5, ""), rec(6, "\n")];
        assert_eq!(
            labelled(&recs),
            [
                "cta 1 warp 2 lane  0> a",
                "cta 1 warp 2 lane  3> b",
                "cta 1 warp 2 lane  3> c",
                "cta 1 warp 2 lane  4> no newline",
                "cta 1 warp 2 lane  6> ",
            ]
        );
    }
}
