//! Control-flow graph of a function and immediate post-dominators, which give
//! each branch its reconvergence point (the PC where a diverged warp's paths meet).

use crate::ptx::ir::{Function, Kind};

/// Reconvergence PC meaning "never: paths meet only when their threads finish".
pub const EXIT_PC: u32 = u32::MAX;

/// A basic block: instructions `[start, end)`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Block {
    /// First instruction.
    pub start: u32,
    /// One past the last instruction.
    pub end: u32,
    /// Successor blocks (`None` = the virtual exit).
    pub succs: Vec<Option<usize>>,
}

/// The CFG of one function with its post-dominator information.
#[derive(Debug, Clone)]
pub struct Cfg {
    /// Basic blocks in instruction order.
    pub blocks: Vec<Block>,
    /// Block of each instruction.
    pub block_of: Vec<u32>,
    /// Immediate post-dominator of each block (`None` = the virtual exit).
    pub ipdom: Vec<Option<usize>>,
    /// Reconvergence PC of each instruction (meaningful for branches), or [`EXIT_PC`].
    pub reconv: Vec<u32>,
}

impl Cfg {
    /// Builds the CFG of `f`.
    pub fn build(f: &Function) -> Cfg {
        let n = f.insts.len();
        let mut leader = vec![false; n + 1];
        if n > 0 {
            leader[0] = true;
        }
        for (pc, i) in f.insts.iter().enumerate() {
            match &i.kind {
                Kind::Bra { target, .. } => {
                    leader[*target as usize] = true;
                    leader[pc + 1] = true;
                }
                Kind::Ret | Kind::Exit | Kind::Trap => leader[pc + 1] = true,
                _ => {}
            }
        }
        let mut blocks = Vec::new();
        let mut block_of = vec![0u32; n];
        let mut start = 0;
        for pc in 1..=n {
            if leader[pc] || pc == n {
                if start < pc {
                    for b in &mut block_of[start..pc] {
                        *b = blocks.len() as u32;
                    }
                    blocks.push(Block { start: start as u32, end: pc as u32, succs: Vec::new() });
                }
                start = pc;
            }
        }
        let block_at = |pc: u32| -> Option<usize> { ((pc as usize) < n).then(|| block_of[pc as usize] as usize) };
        for blk in &mut blocks {
            let last = blk.end - 1;
            let inst = &f.insts[last as usize];
            let fall = block_at(last + 1);
            let guarded = inst.guard.is_some();
            let mut succs = Vec::new();
            match &inst.kind {
                Kind::Bra { target, .. } => {
                    succs.push(block_at(*target));
                    if guarded {
                        succs.push(fall);
                    }
                }
                Kind::Ret | Kind::Exit | Kind::Trap => {
                    succs.push(None);
                    if guarded {
                        succs.push(fall);
                    }
                }
                _ => succs.push(fall),
            }
            succs.dedup();
            blk.succs = succs;
        }
        let ipdom = post_dominators(&blocks);
        let reconv = (0..n)
            .map(|pc| match ipdom[block_of[pc] as usize] {
                Some(b) => blocks[b].start,
                None => EXIT_PC,
            })
            .collect();
        Cfg { blocks, block_of, ipdom, reconv }
    }
}

/// Immediate post-dominators by the iterative algorithm of Cooper, Harvey and
/// Kennedy on the reversed graph, rooted at a virtual exit node (index `nb`).
fn post_dominators(blocks: &[Block]) -> Vec<Option<usize>> {
    let nb = blocks.len();
    let exit = nb;
    // predecessors in the reversed graph = successors in the CFG
    let mut rpreds: Vec<Vec<usize>> = vec![Vec::new(); nb + 1];
    for (b, blk) in blocks.iter().enumerate() {
        for s in &blk.succs {
            rpreds[b].push(s.unwrap_or(exit));
        }
    }
    // reversed-graph successors of node x = CFG predecessors of x
    let mut rsuccs: Vec<Vec<usize>> = vec![Vec::new(); nb + 1];
    for (b, ps) in rpreds.iter().enumerate() {
        for &p in ps {
            rsuccs[p].push(b);
        }
    }
    // reverse post-order of the reversed graph from exit (iterative DFS)
    let mut order = Vec::with_capacity(nb + 1);
    let mut seen = vec![false; nb + 1];
    let mut stack = vec![(exit, 0usize)];
    seen[exit] = true;
    while let Some((node, k)) = stack.pop() {
        if k < rsuccs[node].len() {
            stack.push((node, k + 1));
            let nx = rsuccs[node][k];
            if !seen[nx] {
                seen[nx] = true;
                stack.push((nx, 0));
            }
        } else {
            order.push(node);
        }
    }
    order.reverse();
    let mut rpo_num = vec![usize::MAX; nb + 1];
    for (i, &b) in order.iter().enumerate() {
        rpo_num[b] = i;
    }
    let mut idom: Vec<Option<usize>> = vec![None; nb + 1];
    idom[exit] = Some(exit);
    let intersect = |idom: &[Option<usize>], mut a: usize, mut b: usize| {
        while a != b {
            while rpo_num[a] > rpo_num[b] {
                a = idom[a].expect("processed");
            }
            while rpo_num[b] > rpo_num[a] {
                b = idom[b].expect("processed");
            }
        }
        a
    };
    let mut changed = true;
    while changed {
        changed = false;
        for &b in order.iter().skip(1) {
            let mut new = None;
            for &p in &rpreds[b] {
                if idom[p].is_some() {
                    new = Some(match new {
                        None => p,
                        Some(n) => intersect(&idom, p, n),
                    });
                }
            }
            if new.is_some() && idom[b] != new {
                idom[b] = new;
                changed = true;
            }
        }
    }
    (0..nb).map(|b| idom[b].filter(|&d| d != exit)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ptx;

    fn cfg_of(body: &str) -> (crate::ptx::Program, Cfg) {
        let src = format!(
            ".version 7.8\n.target sm_90\n.address_size 64\n.entry k()\n{{\n.reg .pred %p<3>;\n.reg .b32 %r<4>;\n{body}\n}}\n"
        );
        let p = ptx::load(&src, "t.ptx").unwrap();
        let c = Cfg::build(&p.functions[0]);
        (p, c)
    }

    #[test]
    fn if_else_reconverges_at_join() {
        let (_, c) = cfg_of(
            "@%p1 bra ELSE;\n add.s32 %r1, %r1, 1;\n bra.uni JOIN;\nELSE:\n add.s32 %r1, %r1, 2;\nJOIN:\n add.s32 %r2, %r1, 1;\n ret;",
        );
        // pc 0: branch; join is pc 4
        assert_eq!(c.reconv[0], 4);
    }

    #[test]
    fn loop_with_break_reconverges_after_loop() {
        let (_, c) = cfg_of("LOOP:\n add.s32 %r1, %r1, 1;\n @%p1 bra OUT;\n @%p2 bra LOOP;\nOUT:\n ret;");
        assert_eq!(c.reconv[1], 3);
        assert_eq!(c.reconv[2], 3);
    }

    #[test]
    fn early_exit_reconverges_at_exit() {
        let (_, c) = cfg_of("@%p1 bra A;\n ret;\nA:\n add.s32 %r1, %r1, 1;\n ret;");
        assert_eq!(c.reconv[0], EXIT_PC);
    }

    #[test]
    fn infinite_loop_has_exit_reconvergence() {
        let (_, c) = cfg_of("L:\n @%p1 bra L;\n bra.uni L;");
        assert_eq!(c.reconv[0], EXIT_PC);
    }
}
