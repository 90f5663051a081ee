//! Hazards as the checkers find them (instruction indices, warps, lane masks),
//! merged across CTAs in an order-independent way, and turned into
//! [`Report`]s with names (PTX and CUDA lines, buffers and indices).

use std::collections::BTreeMap;

use super::{Hazard, Report, Site};
use crate::ptx::ir::{MemSpace, Program};
use crate::sim::memory::Allocation;

/// An instruction: function index and instruction index.
pub type Pc = (u32, u32);

/// What makes two findings the same hazard: its class, space and the
/// instructions involved (the later access first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Key {
    /// The class.
    pub hazard: Hazard,
    /// The space (shared, global, local; `Generic` for barriers).
    pub space: SpaceKey,
    /// The instruction that found the hazard.
    pub at: Pc,
    /// The earlier instruction it conflicts with, if any.
    pub with: Option<Pc>,
}

/// [`MemSpace`] as an ordered key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SpaceKey {
    /// Shared memory.
    Shared,
    /// Global memory.
    Global,
    /// Local memory.
    Local,
    /// No memory (barriers).
    None,
}

impl SpaceKey {
    /// From a resolved space.
    pub fn of(s: MemSpace) -> SpaceKey {
        match s {
            MemSpace::Shared => SpaceKey::Shared,
            MemSpace::Global => SpaceKey::Global,
            MemSpace::Local => SpaceKey::Local,
            _ => SpaceKey::None,
        }
    }
}

/// One example of a hazard and how often it occurred.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Example {
    /// Linear CTA of the access that found it.
    pub cta: u32,
    /// Its warp and lanes.
    pub warp: u32,
    /// Lanes (bit per lane).
    pub lanes: u32,
    /// The other party: linear CTA, warp, lanes (none for uninitialised reads).
    pub other: Option<(u32, u32, u32)>,
    /// The address (space offset for shared and local, device address for global).
    pub addr: u64,
    /// Bytes per element of the access (to name an index).
    pub elem: u32,
    /// Occurrences (lane-level hazards) over all CTAs.
    pub count: u64,
}

/// Hazards found so far, by [`Key`].
#[derive(Debug, Default)]
pub struct Findings {
    /// The findings.
    pub map: BTreeMap<Key, Example>,
}

impl Findings {
    /// Records one occurrence. Within one CTA, the first example is kept and
    /// lanes of the same warps are added to it.
    #[allow(clippy::too_many_arguments)]
    pub fn add(
        &mut self,
        key: Key,
        cta: u32,
        warp: u32,
        lane: u32,
        other: Option<(u32, u32, u32)>,
        addr: u64,
        elem: u32,
    ) {
        let e = self.map.entry(key).or_insert(Example { cta, warp, lanes: 0, other, addr, elem, count: 0 });
        e.count += 1;
        if e.cta == cta && e.warp == warp {
            e.lanes |= 1 << lane;
            if let (Some(o), Some(n)) = (&mut e.other, other)
                && o.0 == n.0
                && o.1 == n.1
            {
                o.2 |= n.2;
            }
        }
    }

    /// Merges another CTA's findings: counts add up, the example of the lowest
    /// CTA index stays, so the result does not depend on the merge order.
    pub fn merge(&mut self, other: Findings) {
        for (k, e) in other.map {
            match self.map.get_mut(&k) {
                None => {
                    self.map.insert(k, e);
                }
                Some(mine) => {
                    let count = mine.count + e.count;
                    if (e.cta, e.warp) < (mine.cta, mine.warp) {
                        *mine = e;
                    }
                    mine.count = count;
                }
            }
        }
    }

    /// The reports, in key order.
    pub fn reports(&self, names: &Names) -> Vec<Report> {
        self.map.iter().map(|(k, e)| names.report(k, e)).collect()
    }
}

/// What turns indices into names: the program, the launch shape, the device
/// allocations and the element sizes of named buffers.
pub struct Names<'a> {
    /// The program.
    pub prog: &'a Program,
    /// The kernel.
    pub kernel: String,
    /// Grid size.
    pub grid: [u32; 3],
    /// Block size.
    pub block: [u32; 3],
    /// Device allocations.
    pub allocations: &'a [Allocation],
    /// Element size of buffers by name (default: the access's element size).
    pub elem_sizes: &'a [(String, u32)],
}

impl Names<'_> {
    /// CTA index (x, y, z) of a linear one.
    pub fn cta(&self, linear: u32) -> [u32; 3] {
        let [gx, gy, _] = self.grid;
        [linear % gx, (linear / gx) % gy, linear / (gx * gy)]
    }

    /// Thread index (x, y, z) of warp `warp`, lane `lane`.
    pub fn thread(&self, warp: u32, lane: u32) -> [u32; 3] {
        let [bx, by, _] = self.block;
        let t = warp * 32 + lane;
        [t % bx, (t / bx) % by, t / (bx * by)]
    }

    /// An instruction with who executed it.
    pub fn site(&self, (func, pc): Pc, cta: u32, warp: u32, lanes: u32) -> Site {
        let f = &self.prog.functions[func as usize];
        let info = f.info.get(pc as usize);
        let ptx_line = info.map(|i| i.ptx_line).unwrap_or(0);
        let ptx_text =
            ptx_line.checked_sub(1).and_then(|l| self.prog.ptx_lines.get(l as usize)).map(|t| t.trim().to_string());
        let source = info
            .and_then(|i| i.src)
            .filter(|s| s.line > 0)
            .map(|s| (self.prog.files.get(s.file as usize).cloned().unwrap_or_default(), s.line));
        let first = if lanes == 0 { 0 } else { lanes.trailing_zeros() };
        Site {
            function: f.name.clone(),
            pc,
            ptx_line,
            ptx_text: ptx_text.unwrap_or_default(),
            source,
            cta: self.cta(cta),
            warp,
            lanes,
            first_thread: self.thread(warp, first),
        }
    }

    /// `name[index]` for an address, with how it relates to the buffer.
    pub fn location(&self, space: SpaceKey, addr: u64, elem: u32) -> String {
        let elem = elem.max(1) as u64;
        match space {
            SpaceKey::Shared => {
                let var = self.prog.shared_vars.iter().filter(|v| v.offset as u64 <= addr).max_by_key(|v| v.offset);
                match var {
                    Some(v) if v.size == 0 || addr < v.offset as u64 + v.size as u64 => {
                        format!("{}[{}] (shared offset {addr:#x})", short(&v.name), (addr - v.offset as u64) / elem)
                    }
                    _ => format!("shared offset {addr:#x}"),
                }
            }
            SpaceKey::Global => match self.allocations.iter().find(|a| addr >= a.base && addr < a.base + a.len) {
                Some(a) => {
                    let e = self.elem_of(&a.name, elem);
                    format!("{}[{}]", a.name, (addr - a.base) / e)
                }
                None => format!("global address {addr:#x}"),
            },
            SpaceKey::Local => format!("local offset {addr:#x}"),
            SpaceKey::None => String::new(),
        }
    }

    /// The element size of buffer `name` (else `default`).
    pub fn elem_of(&self, name: &str, default: u64) -> u64 {
        self.elem_sizes.iter().find(|(n, _)| n == name).map(|&(_, s)| s as u64).unwrap_or(default).max(1)
    }

    fn report(&self, k: &Key, e: &Example) -> Report {
        let mut sites = vec![self.site(k.at, e.cta, e.warp, e.lanes)];
        if let (Some(with), Some((cta, warp, lanes))) = (k.with, e.other) {
            sites.push(self.site(with, cta, warp, lanes));
        }
        Report {
            hazard: k.hazard,
            space: space_name(k.space),
            kernel: self.kernel.clone(),
            location: self.location(k.space, e.addr, e.elem),
            sites,
            count: e.count,
            note: String::new(),
        }
    }
}

/// A space's name in reports.
pub fn space_name(s: SpaceKey) -> String {
    match s {
        SpaceKey::Shared => "shared",
        SpaceKey::Global => "global",
        SpaceKey::Local => "local",
        SpaceKey::None => "",
    }
    .to_string()
}

/// A shared variable's name without clang's mangling (`_ZZ9block_sumE4part` → `part`).
fn short(name: &str) -> String {
    // _ZZ<len><function>E<len><name>
    if let Some(rest) = name.strip_prefix("_ZZ")
        && let Some(e) = rest.rfind('E')
    {
        let tail = &rest[e + 1..];
        let digits = tail.chars().take_while(|c| c.is_ascii_digit()).count();
        if digits > 0 && digits < tail.len() {
            return tail[digits..].to_string();
        }
    }
    name.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_names_lose_their_mangling() {
        assert_eq!(short("_ZZ16block_sum_nosyncE4part"), "part");
        assert_eq!(short("tile"), "tile");
    }

    #[test]
    fn merging_keeps_the_lowest_cta_whatever_the_order() {
        let k = Key { hazard: Hazard::ReadAfterWrite, space: SpaceKey::Shared, at: (0, 1), with: Some((0, 2)) };
        let one = |cta| {
            let mut f = Findings::default();
            f.add(k, cta, 1, 3, Some((cta, 0, 1)), 8, 4);
            f
        };
        let (mut a, mut b) = (one(5), one(2));
        a.merge(one(2));
        b.merge(one(5));
        assert_eq!(a.map, b.map);
        assert_eq!(a.map[&k].cta, 2);
        assert_eq!(a.map[&k].count, 2);
    }
}
