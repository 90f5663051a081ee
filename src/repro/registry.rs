//! One registry of every table of every thesis: what each table is (title as
//! printed, seed lines, scenes), how far it is reproduced, which measurement
//! groups it needs and how it is rendered from their raw measurements.
//!
//! Tables are addressed as `thesis:id` (`fabianowski:4.5`, `purcell:1`); a
//! bare id (`4.5`) works while exactly one reproduced table has it.

use serde::Serialize;

use super::results::{Results, Sample};
use super::table::Table;
use super::{engelhardt2013, fabianowski2011, lin2017, purcell2003, zeidan2011};
use crate::host::kdtree::{BuildParams, Heuristic, KdTree, build};
use crate::host::scene::Scene;

/// A thesis (or paper) whose tables warplight reproduces.
#[derive(Debug)]
pub struct Thesis {
    /// Short name used in addresses: `fabianowski`.
    pub short: &'static str,
    /// Module and kernel directory: `fabianowski2011` (`src/repro/…`, `kernels/…`).
    pub dir: &'static str,
    /// Seed number in `shared/seeds/`.
    pub seed: &'static str,
    /// The seed's text file in `shared/seeds/` (line numbers refer to it).
    pub seed_file: &'static str,
    /// Author(s), year and title.
    pub citation: &'static str,
    /// Its tables, in the document's order.
    pub tables: &'static [TableDef],
    /// Its measurement groups.
    pub groups: &'static [Group],
}

/// How far a table is reproduced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Status {
    /// Every reproducible column measured on the emulator (or host code standing for the thesis').
    Reproduced,
    /// Reproduced through a model (timing), not measured.
    Modelled,
    /// Some columns or only a qualitative finding.
    Partly,
    /// Not reproduced yet.
    Missing,
    /// Cannot be reproduced here (third-party software or hardware); the note says why.
    NotReproducible,
    /// Not a measurement (definitions, scene properties, parameters).
    NotAMeasurement,
}

impl Status {
    /// As `--list` prints it.
    pub fn name(&self) -> &'static str {
        match self {
            Status::Reproduced => "reproduced",
            Status::Modelled => "modelled",
            Status::Partly => "partly",
            Status::Missing => "missing",
            Status::NotReproducible => "not reproducible",
            Status::NotAMeasurement => "not a measurement",
        }
    }
}

/// Renders a table (or its parts) from raw measurements.
pub type Render = fn(&Entry, &Results) -> Vec<Table>;

/// One table of a thesis.
#[derive(Debug)]
pub struct TableDef {
    /// The number as printed: `4.5`, `1`, `A.1`.
    pub id: &'static str,
    /// The caption as printed.
    pub title: &'static str,
    /// Seed lines: `L1878-1888`.
    pub lines: &'static str,
    /// Status.
    pub status: Status,
    /// What is reproduced how, or why not (one line).
    pub note: &'static str,
    /// The scenes of the table, in its order (names in `scenes/`).
    pub scenes: &'static [&'static str],
    /// The measurement groups it is rendered from.
    pub groups: &'static [&'static str],
    /// How it is rendered; `None` while missing.
    pub render: Option<Render>,
}

/// Progress of a measurement: one unit of work done.
pub struct Tick<'a> {
    /// Frame, when frame-based.
    pub frame: Option<u32>,
    /// Variant being run.
    pub variant: &'a str,
}

/// What a measurement gets: the scene, its trees (built once per scene and
/// heuristic, shared by the groups), the frames and the image side.
pub struct Workspace<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Frames of the flight to run (already clipped to the flight).
    pub frames: std::ops::Range<u32>,
    /// Image side.
    pub resolution: u32,
    /// Repetitions of timed work (tree builds); the fastest counts.
    pub repeats: u32,
    trees: Vec<(Heuristic, KdTree)>,
}

impl<'a> Workspace<'a> {
    /// A workspace for one scene.
    pub fn new(scene: &'a Scene, frames: std::ops::Range<u32>, resolution: u32) -> Workspace<'a> {
        Workspace { scene, frames, resolution, repeats: 1, trees: Vec::new() }
    }

    /// Builds the scene's kd-tree by `h` with the thesis' parameters, unless built already.
    pub fn build(&mut self, h: Heuristic) {
        if !self.trees.iter().any(|(x, _)| *x == h) {
            let tris: Vec<[glam::Vec3; 3]> = self.scene.triangles.iter().map(|t| t.v).collect();
            self.trees.push((h, build(&tris, BuildParams::thesis(h))));
        }
    }

    /// Keeps a tree built elsewhere (a timed build) for the other groups.
    pub fn keep(&mut self, h: Heuristic, tree: KdTree) {
        if !self.trees.iter().any(|(x, _)| *x == h) {
            self.trees.push((h, tree));
        }
    }

    /// The tree by `h`; [`Workspace::build`] it first.
    pub fn tree(&self, h: Heuristic) -> &KdTree {
        &self.trees.iter().find(|(x, _)| *x == h).expect("Workspace::build before Workspace::tree").1
    }
}

/// A measurement failed.
pub type MeasureError = Box<dyn std::error::Error + Send + Sync>;

/// Measures a group on one scene, calling `tick` once per frame and variant.
pub type Measure = fn(&mut Workspace, &mut dyn FnMut(Tick)) -> Result<Vec<Sample>, MeasureError>;

/// A measurement group: runs shared by tables (4.5, 4.6 and 4.7 share the traversal runs).
#[derive(Debug)]
pub struct Group {
    /// Name, `fabianowski/traversal`.
    pub name: &'static str,
    /// What it runs (for the plan printed before a run).
    pub what: &'static str,
    /// Whether it runs per frame of the flight (otherwise once per scene, by the shard starting at frame 0).
    pub per_frame: bool,
    /// Variants run per frame (progress units per frame).
    pub variants: usize,
    /// Estimated core-seconds per frame and variant, per pixel of the image's
    /// side: the emulated kernels' time grows about linearly with the side at
    /// the sizes we run (an emulated Sponza frame of one variant takes about
    /// 1.1 s at 96 × 96 and 5.5 s at 512 × 512 on two cores).
    pub seconds_per_side: f64,
    /// Estimated core-seconds per triangle of its own work once per scene (timed builds).
    pub seconds_per_triangle: f64,
    /// The image side it runs at: the protocol's, capped, or its own (the
    /// plan says so where the protocol's is not what runs).
    pub side: Side,
    /// The kd-trees it runs on (built once per scene for all groups).
    pub trees: &'static [Heuristic],
    /// The measurement.
    pub measure: Measure,
}

/// The image side a group runs at.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The protocol's resolution.
    Protocol,
    /// The protocol's, at most this many pixels.
    AtMost(u32),
    /// Its own, whatever the protocol's: the pixels, and what fixes them.
    Fixed(u32, &'static str),
    /// An image of its own that no square side describes (what it is); its
    /// estimate takes no side.
    Own(&'static str),
}

impl Side {
    /// The side it runs at under a protocol of `protocol` pixels.
    pub fn of(self, protocol: u32) -> u32 {
        match self {
            Side::Protocol => protocol,
            Side::AtMost(m) => protocol.min(m),
            Side::Fixed(n, _) => n,
            Side::Own(_) => 0,
        }
    }

    /// What the plan says of it under a protocol of `protocol` pixels (empty when it runs the protocol's).
    pub fn note(self, protocol: u32) -> String {
        match self {
            Side::AtMost(m) if protocol > m => {
                format!(" (at most {m}x{m} pixels: the protocol's {protocol}x{protocol} is capped)")
            }
            Side::Fixed(n, why) if n != protocol => {
                format!(" (at {n}x{n} pixels, {why}: the protocol's {protocol}x{protocol} does not apply)")
            }
            Side::Own(what) => format!(" ({what}: the protocol's {protocol}x{protocol} does not apply)"),
            _ => String::new(),
        }
    }
}

/// Estimated seconds per triangle to build a tree by `h`, single-threaded
/// (measured on this project's machine class: SAH and SIROH trees of Sponza
/// 0.27 s; the numerical approximation's trees of Sponza about 19 s and of
/// the Conference room about 65 s).
pub fn tree_seconds_per_triangle(h: Heuristic) -> f64 {
    match h {
        Heuristic::Numerical => 2.5e-4,
        _ => 5e-6,
    }
}

/// Every thesis, in seed order.
pub static THESES: [&Thesis; 5] =
    [&fabianowski2011::THESIS, &engelhardt2013::THESIS, &zeidan2011::THESIS, &lin2017::THESIS, &purcell2003::THESIS];

/// A table with its thesis.
#[derive(Debug, Clone, Copy)]
pub struct Entry {
    /// The thesis.
    pub thesis: &'static Thesis,
    /// The table.
    pub table: &'static TableDef,
}

impl Entry {
    /// `fabianowski:4.5`.
    pub fn address(&self) -> String {
        format!("{}:{}", self.thesis.short, self.table.id)
    }

    /// The heading printed above the table: number, caption as printed, seed and lines.
    pub fn heading(&self) -> String {
        format!(
            "{} Table {}: {} (seed {}, {})",
            self.thesis.short, self.table.id, self.table.title, self.thesis.seed, self.table.lines
        )
    }

    /// The groups it needs.
    pub fn groups(&self) -> Vec<&'static Group> {
        self.table.groups.iter().filter_map(|g| self.thesis.groups.iter().find(|x| x.name == *g)).collect()
    }
}

/// Every table of every thesis.
pub fn entries() -> Vec<Entry> {
    entries_of(&THESES)
}

/// Every table of `theses`.
pub fn entries_of(theses: &[&'static Thesis]) -> Vec<Entry> {
    theses.iter().flat_map(|t| t.tables.iter().map(move |table| Entry { thesis: t, table })).collect()
}

/// The lowest fidelity level the measurements of `e` need (`tables` runs at
/// the highest of its tables' levels unless `--fidelity` says otherwise):
/// Fabianowski's cache tables (4.8–4.10) read texture-cache hits, and so do
/// his frame-rate tables (4.1, 4.6: the GTX 280 timing model charges a
/// texture miss more latency than a hit); his other emulated tables read
/// instructions and transactions, not hits, and Table 5.1 only what its
/// kernels write; Lin's
/// Fig. 3 reads instructions; tables that run no kernel need nothing. Any
/// other emulated table gets the full model.
pub fn lowest_fidelity(e: &Entry) -> crate::sim::Fidelity {
    use crate::sim::Fidelity;
    match (e.thesis.short, e.table.id) {
        _ if e.table.render.is_none() => Fidelity::Functional,
        ("fabianowski", "4.2" | "4.3" | "4.4" | "4.5" | "4.7") => Fidelity::Memory,
        // Table 5.1 reads what its kernels write (interactions, kernels, contributions), no counter
        ("fabianowski", "5.1") => Fidelity::Functional,
        ("lin", "fig3") => Fidelity::Instructions,
        _ => Fidelity::Caches,
    }
}

/// Why an address did not resolve.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AddressError {
    /// Unknown thesis.
    #[error("no thesis {0:?}; theses: {1}")]
    Thesis(String, String),
    /// Unknown table.
    #[error("{0} has no table {1}; its tables: {2}")]
    Table(String, String, String),
    /// A bare id several reproduced tables have.
    #[error("table {0} is ambiguous: {1}; name one")]
    Ambiguous(String, String),
    /// Known but not reproduced (yet).
    #[error("{0} is not reproduced ({1}); `warplight tables --list` shows what is")]
    NotReproduced(String, String),
}

/// Resolves addresses: `fabianowski:4.5`, `4.5`, `fabianowski:all`, `all`.
pub fn resolve(addresses: &[String]) -> Result<Vec<Entry>, AddressError> {
    resolve_in(&THESES, addresses)
}

/// [`resolve`] among `theses`.
pub fn resolve_in(theses: &[&'static Thesis], addresses: &[String]) -> Result<Vec<Entry>, AddressError> {
    let all = entries_of(theses);
    let runnable = |e: &Entry| e.table.render.is_some();
    let mut out: Vec<Entry> = Vec::new();
    let push = |e: Entry, out: &mut Vec<Entry>| {
        if !out.iter().any(|x| x.address() == e.address()) {
            out.push(e);
        }
    };
    for a in addresses {
        let a = a.trim();
        if a == "all" {
            for e in all.iter().filter(|e| runnable(e)) {
                push(*e, &mut out);
            }
            continue;
        }
        if let Some((t, id)) = a.split_once(':') {
            let Some(thesis) = theses.iter().find(|x| x.short == t || x.dir == t) else {
                let names: Vec<&str> = theses.iter().map(|x| x.short).collect();
                return Err(AddressError::Thesis(t.into(), names.join(", ")));
            };
            let of_thesis: Vec<&Entry> = all.iter().filter(|e| e.thesis.short == thesis.short).collect();
            if id == "all" {
                for e in of_thesis.into_iter().filter(|e| runnable(e)) {
                    push(*e, &mut out);
                }
                continue;
            }
            let Some(e) = of_thesis.iter().find(|e| e.table.id.eq_ignore_ascii_case(id)) else {
                let ids: Vec<&str> = of_thesis.iter().map(|e| e.table.id).collect();
                return Err(AddressError::Table(thesis.short.into(), id.into(), ids.join(", ")));
            };
            if !runnable(e) {
                return Err(AddressError::NotReproduced(e.address(), e.table.status.name().into()));
            }
            push(**e, &mut out);
            continue;
        }
        let same: Vec<&Entry> = all.iter().filter(|e| e.table.id.eq_ignore_ascii_case(a)).collect();
        let run: Vec<&Entry> = same.iter().copied().filter(|e| runnable(e)).collect();
        match (run.len(), same.len()) {
            (1, _) => push(*run[0], &mut out),
            (0, 0) => {
                let ids: Vec<String> = all.iter().filter(|e| runnable(e)).map(|e| e.address()).collect();
                return Err(AddressError::Table("no thesis".into(), a.into(), ids.join(", ")));
            }
            (0, _) => {
                let names: Vec<String> =
                    same.iter().map(|e| format!("{} ({})", e.address(), e.table.status.name())).collect();
                return Err(AddressError::NotReproduced(a.into(), names.join(", ")));
            }
            _ => {
                let names: Vec<String> = run.iter().map(|e| e.address()).collect();
                return Err(AddressError::Ambiguous(a.into(), names.join(", ")));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The side a group runs at, and what the plan says of it.
    #[test]
    fn sides_run_and_say_what_they_are() {
        assert_eq!((Side::Protocol.of(96), Side::Protocol.note(96)), (96, String::new()));
        assert_eq!(Side::AtMost(32).of(96), 32);
        assert_eq!(Side::AtMost(32).of(16), 16);
        assert!(Side::AtMost(32).note(96).contains("at most 32x32 pixels: the protocol's 96x96 is capped"));
        assert_eq!(Side::AtMost(32).note(16), "");
        let f = Side::Fixed(64, "its truth's");
        assert_eq!((f.of(96), f.of(512)), (64, 64));
        assert!(f.note(96).contains("at 64x64 pixels, its truth's: the protocol's 96x96 does not apply"));
        assert_eq!(f.note(64), "");
        assert_eq!(Side::Own("an 8x4 image").of(96), 0);
        assert!(Side::Own("an 8x4 image").note(96).contains("an 8x4 image: the protocol's 96x96 does not apply"));
    }

    #[test]
    fn addresses_resolve() {
        let r = resolve(&["fabianowski:4.5".into(), "4.7".into(), "4.5".into()]).unwrap();
        let names: Vec<String> = r.iter().map(|e| e.address()).collect();
        assert_eq!(names, ["fabianowski:4.5", "fabianowski:4.7"]);
        assert!(matches!(resolve(&["nobody:1".into()]), Err(AddressError::Thesis(..))));
        assert!(matches!(resolve(&["fabianowski:9.9".into()]), Err(AddressError::Table(..))));
        // a table that exists but is not reproduced: a clear error, not "unknown"
        let e = resolve(&["lin:3".into()]).unwrap_err();
        assert!(matches!(e, AddressError::NotReproduced(..)), "{e}");
        let all = resolve(&["all".into()]).unwrap();
        assert!(all.len() >= 10);
    }

    fn render_nothing(_: &Entry, _: &Results) -> Vec<Table> {
        Vec::new()
    }

    fn def(id: &'static str, render: Option<Render>) -> TableDef {
        TableDef {
            id,
            title: "t",
            lines: "L1",
            status: if render.is_some() { Status::Reproduced } else { Status::Missing },
            note: "",
            scenes: &[],
            groups: &[],
            render,
        }
    }

    #[test]
    fn a_bare_id_resolves_while_one_reproduced_table_has_it() {
        static A_TABLES: std::sync::LazyLock<[TableDef; 2]> =
            std::sync::LazyLock::new(|| [def("1", Some(render_nothing)), def("2", Some(render_nothing))]);
        static B_TABLES: std::sync::LazyLock<[TableDef; 2]> =
            std::sync::LazyLock::new(|| [def("1", Some(render_nothing)), def("2", None)]);
        static A: std::sync::LazyLock<Thesis> = std::sync::LazyLock::new(|| Thesis {
            short: "a",
            dir: "a2000",
            seed: "9",
            seed_file: "",
            citation: "",
            tables: &*A_TABLES,
            groups: &[],
        });
        static B: std::sync::LazyLock<Thesis> = std::sync::LazyLock::new(|| Thesis {
            short: "b",
            dir: "b2000",
            seed: "9",
            seed_file: "",
            citation: "",
            tables: &*B_TABLES,
            groups: &[],
        });
        let theses: [&'static Thesis; 2] = [&A, &B];
        // "2" is reproduced only in a: it resolves there; "1" is reproduced in both: ambiguous
        let r = resolve_in(&theses, &["2".into()]).unwrap();
        assert_eq!(r[0].address(), "a:2");
        let e = resolve_in(&theses, &["1".into()]).unwrap_err();
        assert_eq!(e.to_string(), "table 1 is ambiguous: a:1, b:1; name one");
        assert_eq!(resolve_in(&theses, &["b:1".into(), "a2000:1".into()]).unwrap().len(), 2);
        assert!(matches!(resolve_in(&theses, &["b:2".into()]), Err(AddressError::NotReproduced(..))));
        assert_eq!(resolve_in(&theses, &["b:all".into()]).unwrap().len(), 1);
    }

    #[test]
    fn every_table_is_registered_once_with_its_groups() {
        let all = entries();
        for (i, e) in all.iter().enumerate() {
            assert!(!all[..i].iter().any(|x| x.address() == e.address()), "{} twice", e.address());
            assert_eq!(e.groups().len(), e.table.groups.len(), "{}: unknown group", e.address());
            // a table is rendered from measurements exactly when its status says it is reproduced in some form
            let runs = matches!(e.table.status, Status::Reproduced | Status::Modelled | Status::Partly);
            assert_eq!(e.table.render.is_some(), runs, "{}", e.address());
            assert_eq!(e.table.render.is_some(), !e.table.groups.is_empty(), "{}", e.address());
        }
    }
}
