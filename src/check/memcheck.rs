//! Invalid accesses: out of bounds and misaligned. The emulator stops a
//! launch at the first one as a fault; this names it as a person would: the
//! buffer and the element index (`data[4096]`, one past the end of `data`)
//! instead of a raw address.

use super::findings::{Names, Pc, SpaceKey};
use super::{Hazard, Report};
use crate::ptx::ir::{Kind, MemSpace};
use crate::sim::fault::{Fault, FaultKind};

/// What the faulting instruction does: "read", "write" or "atomic access".
fn verb(names: &Names, (func, pc): Pc) -> &'static str {
    match names.prog.functions[func as usize].insts.get(pc as usize).map(|i| &i.kind) {
        Some(Kind::Ld { .. }) => "read",
        Some(Kind::St { .. }) => "write",
        Some(Kind::Atom { .. }) => "atomic access",
        _ => "access",
    }
}

/// `name[index]` and how the address relates to the nearest buffer, for a
/// global address outside every allocation.
pub fn name_global(names: &Names, addr: u64, size: u32) -> (String, String) {
    let allocs = names.allocations;
    // the buffer the address runs past, else the one it falls before
    let before = allocs.iter().filter(|a| a.base + a.len <= addr).max_by_key(|a| a.base + a.len);
    let after = allocs.iter().filter(|a| a.base > addr).min_by_key(|a| a.base);
    let near = match (before, after) {
        (Some(b), Some(a)) => {
            if addr - (b.base + b.len) <= a.base - addr {
                Some(b)
            } else {
                Some(a)
            }
        }
        (b, a) => b.or(a),
    };
    let Some(a) = near else { return (format!("global address {addr:#x}"), "no buffer is allocated".into()) };
    let e = names.elem_of(&a.name, size as u64);
    let n = a.len / e;
    if addr >= a.base {
        let i = (addr - a.base) / e;
        let past = i - n + 1;
        let how = if past == 1 { "one past the end".to_string() } else { format!("{past} elements past the end") };
        (format!("{}[{i}]", a.name), format!("{how} of `{}` ({n} elements of {e} bytes)", a.name))
    } else {
        let i = (a.base - addr).div_ceil(e);
        (
            format!("{}[-{i}]", a.name),
            format!("{i} elements before the start of `{}` ({n} elements of {e} bytes)", a.name),
        )
    }
}

/// The report for an out-of-bounds or misaligned fault, if it is one.
pub fn from_fault(f: &Fault, names: &Names, at: Pc, cta: u32) -> Option<Report> {
    let lanes = f.lane.map(|l| 1u32 << l).unwrap_or(0);
    let v = verb(names, at);
    let (hazard, space, location, note) = match &f.kind {
        FaultKind::OutOfBounds { space, addr, size } => {
            let (loc, how) = match space {
                MemSpace::Global => name_global(names, *addr, *size),
                MemSpace::Shared => {
                    let loc = names.location(SpaceKey::Shared, *addr, *size);
                    (loc, "past the end of the CTA's shared memory".to_string())
                }
                MemSpace::Local => (format!("local offset {addr:#x}"), "past the thread's local memory".to_string()),
                other => (format!("{other:?} offset {addr:#x}"), "outside the space".to_string()),
            };
            (Hazard::OutOfBounds, *space, loc, format!("{size}-byte {v}, {how}"))
        }
        FaultKind::Misaligned { space, addr, size } => (
            Hazard::Misaligned,
            *space,
            match space {
                MemSpace::Global => names.location(SpaceKey::Global, *addr, *size),
                _ => format!("{space:?} address {addr:#x}"),
            },
            format!("{v} at {addr:#x}, which is not a multiple of {size}"),
        ),
        _ => return None,
    };
    Some(Report {
        hazard,
        space: super::findings::space_name(SpaceKey::of(space)),
        kernel: names.kernel.clone(),
        location,
        sites: vec![names.site(at, cta, f.warp, lanes)],
        count: 1,
        note,
    })
}
