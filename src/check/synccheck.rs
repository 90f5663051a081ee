//! Barriers used wrongly. A `bar.sync` reached by part of a warp's live
//! threads (divergent barrier) and warps waiting at barriers that can never
//! complete (deadlock) stop the launch as faults ([`from_fault`] names them);
//! warps of a CTA released together from *different* `bar.sync` instructions
//! (mismatched barriers: the hardware counts arrivals, so such code runs, but
//! the barriers do not pair up as written) are found as barriers complete
//! ([`Arrivals`]).

use super::findings::{Findings, Key, Names, Pc, SpaceKey};
use super::{Hazard, Report};
use crate::sim::fault::{Fault, FaultKind};

/// Where each warp of a CTA waits.
#[derive(Debug, Clone)]
pub struct Arrivals {
    at: Vec<Option<Pc>>,
}

impl Arrivals {
    /// For `warps` warps.
    pub fn new(warps: usize) -> Self {
        Arrivals { at: vec![None; warps] }
    }

    /// Warp `warp` waits at the barrier instruction `pc`.
    pub fn arrive(&mut self, warp: u32, pc: Pc) {
        self.at[warp as usize] = Some(pc);
    }

    /// A barrier released `warps`: records a mismatch when they waited at
    /// different instructions (the lowest warp's instruction against the
    /// first other one), and forgets their arrivals.
    pub fn release(&mut self, warps: &[usize], cta: u32, lanes: impl Fn(u32) -> u32, found: &mut Findings) {
        let sites: Vec<(u32, Pc)> = warps.iter().filter_map(|&w| self.at[w].map(|p| (w as u32, p))).collect();
        if let Some(&(w0, p0)) = sites.first()
            && let Some(&(w1, p1)) = sites.iter().find(|(_, p)| *p != p0)
        {
            let key = Key { hazard: Hazard::MismatchedBarrier, space: SpaceKey::None, at: p0, with: Some(p1) };
            found.add(key, cta, w0, 0, Some((cta, w1, lanes(w1))), 0, 0);
            if let Some(e) = found.map.get_mut(&key)
                && e.cta == cta
                && e.warp == w0
            {
                e.lanes = lanes(w0);
            }
        }
        for &w in warps {
            self.at[w] = None;
        }
    }
}

/// The report for a barrier fault (divergent barrier, deadlock), if it is one.
pub fn from_fault(f: &Fault, names: &Names, at: Pc, cta: u32) -> Option<Report> {
    let lanes_of = |m: u32| super::lane_list(m);
    let (hazard, lanes, note) = match &f.kind {
        FaultKind::DivergentBarrier { active, live } => (
            Hazard::DivergentBarrier,
            *active,
            format!(
                "lanes {} of warp {} reached the barrier, lanes {} did not (warplight stops here; a GPU may hang or go on)",
                lanes_of(*active),
                f.warp,
                lanes_of(live & !active)
            ),
        ),
        FaultKind::BarrierDeadlock { waiting } => (
            Hazard::BarrierDeadlock,
            0,
            format!(
                "warps wait at barriers that cannot complete: {}",
                waiting.iter().map(|(w, b)| format!("warp {w} at barrier {b}")).collect::<Vec<_>>().join(", ")
            ),
        ),
        FaultKind::MemberMask { mask, lane, active, live } => {
            let why = if mask >> lane & 1 == 0 {
                format!("leaves out lane {lane}, which executes it")
            } else {
                format!("names lanes {} that do not execute it with the others", lanes_of(mask & live & !active))
            };
            (
                Hazard::InvalidMemberMask,
                *active,
                format!(
                    "member mask {mask:#010x} of lane {lane} of warp {} {why} (executing lanes {}); \
                     undefined in PTX (warplight stops here)",
                    f.warp,
                    lanes_of(*active)
                ),
            )
        }
        FaultKind::MemberMaskDiffers { mask, other, other_mask, active } => {
            let lane = f.lane.unwrap_or(active.trailing_zeros());
            (
                Hazard::InvalidMemberMask,
                *active,
                format!(
                    "member mask {mask:#010x} of lane {lane} of warp {} differs from the mask {other_mask:#010x} \
                     of lane {other}, which names lane {lane} (executing lanes {}); undefined in PTX (warplight \
                     stops here)",
                    f.warp,
                    lanes_of(*active)
                ),
            )
        }
        _ => return None,
    };
    Some(Report {
        hazard,
        space: String::new(),
        kernel: names.kernel.clone(),
        location: String::new(),
        sites: vec![names.site(at, cta, f.warp, lanes)],
        count: 1,
        note,
    })
}
