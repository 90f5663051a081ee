//! The interactive terminal view of `warplight step`: CUDA source and PTX
//! side by side at the selected warp's next instruction, its 32-lane active
//! mask, and below one of three panels — the SIMT reconvergence stack (with the
//! CTA's warps), per-lane register values, or the last memory instruction's
//! per-lane addresses with the transactions, sectors or banks they form under
//! the chosen device profile. Fits an 80×24 terminal.
//!
//! Stepping back replays the launch from the start to an earlier step (see
//! [`super::session`]); every action records the step count it started from.
//!
//! [`drive`] runs the view on any ratatui backend with keys from any source,
//! which is how the tests drive it without a terminal.

use std::collections::HashMap;

use ratatui::Frame;
use ratatui::Terminal;
use ratatui::backend::Backend;
use ratatui::crossterm::event::{self, Event, KeyCode, KeyEvent, KeyEventKind, KeyModifiers};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Clear, Paragraph};

use super::breakpoints::Breakpoints;
use super::session::{Error, Session};
use super::sources;
use super::track::{Effect, Tracker};
use crate::model::Profile;
use crate::model::explain;
use crate::sim::access_log::Access;
use crate::sim::stepper::{StepEvent, Stepper, WarpView};

/// Options of the view.
#[derive(Debug, Clone)]
pub struct TuiOptions {
    /// Breakpoints (PTX and source lines); `b` adds PTX-line ones.
    pub breaks: Breakpoints,
    /// Registers listed first in the register panel.
    pub watches: Vec<String>,
    /// The warp selected at the start (CTA slot, warp).
    pub start: (usize, u32),
    /// Profile for the memory panel.
    pub profile: Profile,
    /// Most warp instructions one action may run.
    pub max_steps: u64,
}

/// Runs the view in the terminal until `q`.
pub fn run(session: &Session, o: TuiOptions) -> Result<(), Error> {
    let mut terminal = ratatui::init();
    let r = drive(&mut terminal, session, o, || {
        loop {
            match event::read()? {
                Event::Key(k) if k.kind != KeyEventKind::Release => return Ok(Some(k)),
                Event::Resize(..) => return Ok(Some(KeyEvent::new(KeyCode::Null, KeyModifiers::NONE))),
                _ => {}
            }
        }
    });
    ratatui::restore();
    r.map(|_| ())
}

/// Runs the view on `terminal`, reading keys from `next_key` until it returns
/// `None` or the user quits. Returns the final state.
pub fn drive<B: Backend>(
    terminal: &mut Terminal<B>,
    session: &Session,
    o: TuiOptions,
    mut next_key: impl FnMut() -> Result<Option<KeyEvent>, Error>,
) -> Result<App, Error> {
    let mut app = App::new(session, o)?;
    let mut target = 0u64;
    loop {
        let exit = session.with_stepper(|st| {
            app.replay(st, target)?;
            loop {
                terminal.draw(|f| app.draw(f, st))?;
                let Some(key) = next_key()? else { return Ok(Exit::Quit) };
                match app.handle(key, st)? {
                    Exit::Stay => {}
                    other => return Ok(other),
                }
            }
        })?;
        match exit {
            Exit::Rewind(n) => target = n,
            _ => return Ok(app),
        }
    }
}

/// What an action asks the driver to do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Exit {
    Stay,
    Quit,
    Rewind(u64),
}

/// The lower panel.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Panel {
    /// SIMT stack and the CTA's warps.
    Stack,
    /// Per-lane register values.
    Registers,
    /// The last memory instruction.
    Memory,
}

/// How register values are shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Radix {
    Dec,
    Hex,
    Float,
}

/// A pending prompt for a line number.
#[derive(Debug, Clone, PartialEq, Eq)]
enum Prompt {
    Goto(String),
    Break(String),
}

/// The view's state.
pub struct App {
    o: TuiOptions,
    kernel: String,
    sources: Vec<Option<Vec<String>>>,
    /// Selected CTA slot and warp.
    pub sel: (usize, u32),
    /// Warp instructions issued so far (all warps).
    pub steps: u64,
    history: Vec<u64>,
    /// The lower panel shown.
    pub panel: Panel,
    radix: Radix,
    reg_first: usize,
    last: HashMap<(usize, u32), (StepEvent, Effect)>,
    last_mem: HashMap<(usize, u32), (StepEvent, Vec<Access>)>,
    tracker: Tracker,
    /// The message line.
    pub message: String,
    help: bool,
    prompt: Option<Prompt>,
    /// The fault that stopped the launch, if one did.
    pub fault: Option<String>,
    /// Its PTX line (the PTX pane shows it rather than the warp's next line).
    fault_line: Option<u32>,
}

impl App {
    fn new(session: &Session, o: TuiOptions) -> Result<App, Error> {
        let sources = session.with_stepper(|st| Ok(sources::read_all(&st.module().prog, &session.ptx_path())))?;
        Ok(App {
            sel: o.start,
            o,
            kernel: session.kernel.clone(),
            sources,
            steps: 0,
            history: Vec::new(),
            panel: Panel::Stack,
            radix: Radix::Dec,
            reg_first: 0,
            last: HashMap::new(),
            last_mem: HashMap::new(),
            tracker: Tracker::default(),
            message: "press s to step the selected warp, ? for help".into(),
            help: false,
            prompt: None,
            fault: None,
            fault_line: None,
        })
    }

    /// Brings a fresh stepper to `target` steps, rebuilding the per-warp notes.
    fn replay(&mut self, st: &mut Stepper, target: u64) -> Result<(), Error> {
        self.steps = 0;
        self.fault = None;
        self.fault_line = None;
        self.last.clear();
        self.last_mem.clear();
        self.tracker = Tracker::default();
        while self.steps < target {
            if self.step_one(st)?.is_none() {
                break;
            }
        }
        Ok(())
    }

    /// Issues one warp instruction (any warp, in scheduling order).
    fn step_one(&mut self, st: &mut Stepper) -> Result<Option<(StepEvent, WarpView)>, Error> {
        let Some(ev) = st.step()? else { return Ok(None) };
        self.steps += 1;
        let key = (ev.cta_slot, ev.warp);
        let w = st.warp(ev.cta_slot, ev.warp).ok_or("stepped warp vanished")?;
        let fx = self.tracker.observe(&ev, &w);
        if !ev.accesses.is_empty() {
            self.last_mem.insert(key, (ev.clone(), ev.accesses.clone()));
        }
        self.last.insert(key, (ev.clone(), fx));
        Ok(Some((ev, w)))
    }

    /// Steps until `stop` holds for an event, the grid ends, or the step limit.
    fn run_until(
        &mut self,
        st: &mut Stepper,
        mut stop: impl FnMut(&Self, &StepEvent, &WarpView) -> bool,
    ) -> Result<Option<StepEvent>, Error> {
        for _ in 0..self.o.max_steps {
            match self.step_one(st)? {
                None => {
                    self.message = format!("the grid finished after {} warp instructions", self.steps);
                    return Ok(None);
                }
                Some((ev, w)) => {
                    if stop(self, &ev, &w) {
                        return Ok(Some(ev));
                    }
                }
            }
        }
        self.message = format!("stopped after {} warp instructions (--max-steps)", self.o.max_steps);
        Ok(None)
    }

    fn selected_view(&self, st: &Stepper) -> Option<WarpView> {
        st.warp(self.sel.0, self.sel.1)
    }

    fn describe(&self, ev: &StepEvent) -> String {
        let fx = self.last.get(&(ev.cta_slot, ev.warp)).map(|x| x.1).unwrap_or_default();
        let word = fx.word();
        format!(
            "step {}: warp {}:{} ran PTX {} {} mask {:08x}{}",
            self.steps,
            ev.cta_slot,
            ev.warp,
            ev.ptx_line,
            ev.opcode,
            ev.mask,
            if word.is_empty() { String::new() } else { format!(" - {word}") }
        )
    }

    fn handle(&mut self, key: KeyEvent, st: &mut Stepper) -> Result<Exit, Error> {
        if self.help {
            self.help = false;
            return Ok(Exit::Stay);
        }
        if let Some(p) = self.prompt.take() {
            return self.handle_prompt(p, key, st);
        }
        let ctrl = key.modifiers.contains(KeyModifiers::CONTROL);
        match key.code {
            KeyCode::Char('q') | KeyCode::Esc => return Ok(Exit::Quit),
            KeyCode::Char('c') if ctrl => return Ok(Exit::Quit),
            KeyCode::Char('?') | KeyCode::F(1) => self.help = true,
            KeyCode::Char('s') | KeyCode::Char(' ') | KeyCode::Down => self.act(st, Action::Instruction)?,
            KeyCode::Char('n') => self.act(st, Action::SourceLine)?,
            KeyCode::Char('c') => self.act(st, Action::Continue)?,
            KeyCode::Char('a') => self.act(st, Action::Barrier)?,
            KeyCode::Char('g') => self.prompt = Some(Prompt::Goto(String::new())),
            KeyCode::Char('b') => self.prompt = Some(Prompt::Break(String::new())),
            KeyCode::Char('u') | KeyCode::Backspace | KeyCode::Left => {
                return Ok(match self.history.pop() {
                    Some(n) => {
                        self.message = format!("stepped back to step {n}");
                        Exit::Rewind(n)
                    }
                    None => {
                        self.message = "nothing to step back to".into();
                        Exit::Stay
                    }
                });
            }
            KeyCode::Char('w') | KeyCode::Tab => self.select_warp(st, 1),
            KeyCode::Char('W') | KeyCode::BackTab => self.select_warp(st, -1),
            KeyCode::Char(']') => self.select_cta(st, 1),
            KeyCode::Char('[') => self.select_cta(st, -1),
            KeyCode::Char('1') => self.panel = Panel::Stack,
            KeyCode::Char('2') => self.panel = Panel::Registers,
            KeyCode::Char('3') | KeyCode::Char('m') => self.panel = Panel::Memory,
            KeyCode::Char('x') => {
                self.radix = match self.radix {
                    Radix::Dec => Radix::Hex,
                    Radix::Hex => Radix::Float,
                    Radix::Float => Radix::Dec,
                }
            }
            KeyCode::Char('j') | KeyCode::PageDown => self.reg_first += 1,
            KeyCode::Char('k') | KeyCode::PageUp | KeyCode::Up => self.reg_first = self.reg_first.saturating_sub(1),
            _ => {}
        }
        Ok(Exit::Stay)
    }

    fn handle_prompt(&mut self, p: Prompt, key: KeyEvent, st: &mut Stepper) -> Result<Exit, Error> {
        let (mut text, goto) = match p {
            Prompt::Goto(t) => (t, true),
            Prompt::Break(t) => (t, false),
        };
        match key.code {
            KeyCode::Char(c) if c.is_ascii_digit() => text.push(c),
            KeyCode::Backspace => {
                text.pop();
            }
            KeyCode::Esc => {
                self.message = "cancelled".into();
                return Ok(Exit::Stay);
            }
            KeyCode::Enter => {
                let current = self.selected_view(st).and_then(|w| w.next_ptx_line);
                let line = if text.is_empty() { current } else { text.parse().ok() };
                let Some(line) = line else {
                    self.message = "no line given".into();
                    return Ok(Exit::Stay);
                };
                let has_inst = st.module().prog.functions.iter().flat_map(|f| &f.info).any(|i| i.ptx_line == line);
                if !has_inst {
                    self.message = format!("PTX line {line} holds no instruction");
                } else if goto {
                    self.act(st, Action::Goto(line))?;
                } else {
                    let on = self.o.breaks.toggle_ptx(line);
                    self.message = format!("breakpoint at PTX line {line} {}", if on { "set" } else { "cleared" });
                }
                return Ok(Exit::Stay);
            }
            _ => {}
        }
        self.prompt = Some(if goto { Prompt::Goto(text) } else { Prompt::Break(text) });
        Ok(Exit::Stay)
    }

    fn act(&mut self, st: &mut Stepper, a: Action) -> Result<(), Error> {
        if self.fault.is_some() {
            self.message = "the launch faulted: u steps back, q quits".into();
            return Ok(());
        }
        if st.finished() {
            self.message = "the grid has finished: u steps back, q quits".into();
            return Ok(());
        }
        let start = self.steps;
        let sel = self.sel;
        let Some(w0) = self.selected_view(st) else {
            self.message = "no such warp".into();
            return Ok(());
        };
        if w0.next_pc.is_none() && a != Action::Continue {
            self.message = format!("warp {}:{} has finished; w selects another", sel.0, sel.1);
            return Ok(());
        }
        let start_line = w0.next_source.map(|s| (s.file, s.line));
        let is_sel = move |ev: &StepEvent| (ev.cta_slot, ev.warp) == sel;
        let result = match a {
            Action::Instruction => self.run_until(st, |_, ev, _| is_sel(ev)),
            Action::SourceLine => self.run_until(st, |_, ev, w| {
                let line = w.next_source.map(|s| (s.file, s.line));
                is_sel(ev) && (w.next_pc.is_none() || (line != start_line && line.is_none_or(|l| l.1 != 0)))
            }),
            Action::Goto(l) => self.run_until(st, |_, ev, w| is_sel(ev) && w.next_ptx_line == Some(l)),
            Action::Barrier => self.run_until(st, |_, ev, _| is_sel(ev) && ev.opcode.starts_with("bar")),
            Action::Continue => self.run_until(st, |app, ev, w| app.o.breaks.hit(ev, w).is_some()),
        };
        if self.steps > start {
            self.history.push(start);
        }
        let stopped = match result {
            Ok(s) => s,
            Err(e) => {
                // the launch faulted: keep the view on the faulting warp, show the fault,
                // allow stepping back
                let fault = e
                    .downcast_ref::<Box<crate::sim::fault::Fault>>()
                    .map(|b| &**b)
                    .or_else(|| e.downcast_ref::<crate::sim::fault::Fault>());
                if let Some(f) = fault
                    && let Some(slot) = st.resident_ctas().iter().position(|c| *c == f.cta)
                {
                    self.sel = (slot, f.warp);
                    self.fault_line = Some(f.ptx_line);
                }
                let text = e.to_string().replace('\t', " ");
                self.message = format!("fault: {} (u steps back)", text.lines().next().unwrap_or(""));
                self.fault = Some(text);
                return Ok(());
            }
        };
        if let Some(ev) = stopped {
            if a == Action::Continue {
                self.sel = (ev.cta_slot, ev.warp);
                let line = self.selected_view(st).and_then(|w| w.next_ptx_line).unwrap_or(0);
                self.message = format!("breakpoint: warp {}:{} before PTX line {line}", ev.cta_slot, ev.warp);
            } else {
                self.message = self.describe(&ev);
            }
        }
        Ok(())
    }

    fn select_warp(&mut self, st: &Stepper, d: i64) {
        let n = st.warps_per_cta().max(1) as i64;
        self.sel.1 = (self.sel.1 as i64 + d).rem_euclid(n) as u32;
        self.message = format!("selected warp {}:{}", self.sel.0, self.sel.1);
    }

    fn select_cta(&mut self, st: &Stepper, d: i64) {
        let n = st.resident_ctas().len().max(1) as i64;
        self.sel.0 = (self.sel.0 as i64 + d).rem_euclid(n) as usize;
        self.message = format!("selected CTA slot {} (of {} resident)", self.sel.0, n);
    }

    /// Draws the whole screen.
    pub fn draw(&self, f: &mut Frame, st: &Stepper) {
        let [title, panes, mask, lower, msg, keys] = Layout::vertical([
            Constraint::Length(1),
            Constraint::Min(6),
            Constraint::Length(1),
            Constraint::Length(10),
            Constraint::Length(1),
            Constraint::Length(1),
        ])
        .areas(f.area());
        let w = self.selected_view(st);
        let ctas = st.resident_ctas();
        let cta = ctas.get(self.sel.0).map(|c| format!("({},{},{})", c[0], c[1], c[2])).unwrap_or("-".into());
        let t = format!(
            " {} | CTA {cta} slot {} | warp {} of {} | step {}{} | {}   ? help",
            self.kernel,
            self.sel.0,
            self.sel.1,
            st.warps_per_cta(),
            self.steps,
            if st.finished() { " (finished)" } else { "" },
            self.o.profile.params().name
        );
        f.render_widget(Paragraph::new(t).style(Style::new().add_modifier(Modifier::REVERSED)), title);
        let [left, right] = Layout::horizontal([Constraint::Percentage(50), Constraint::Percentage(50)]).areas(panes);
        self.draw_source(f, left, st, w.as_ref());
        self.draw_ptx(f, right, st, w.as_ref());
        f.render_widget(Paragraph::new(mask_line(w.as_ref())), mask);
        match self.panel {
            Panel::Stack => self.draw_stack(f, lower, st, w.as_ref()),
            Panel::Registers => self.draw_registers(f, lower, st, w.as_ref()),
            Panel::Memory => self.draw_memory(f, lower, st),
        }
        if let Some(fault) = &self.fault {
            f.render_widget(Clear, lower);
            f.render_widget(
                Paragraph::new(fault.as_str())
                    .style(Style::new().fg(Color::Red))
                    .wrap(ratatui::widgets::Wrap { trim: false })
                    .block(Block::default().borders(Borders::ALL).title(" fault (u steps back) ")),
                lower,
            );
        }
        let m = match &self.prompt {
            Some(Prompt::Goto(t)) => format!("run the warp to PTX line: {t}_   (Enter: go, Esc: cancel)"),
            Some(Prompt::Break(t)) => format!("toggle breakpoint at PTX line (empty: current): {t}_"),
            None => self.message.clone(),
        };
        f.render_widget(Paragraph::new(m).style(Style::new().fg(Color::Yellow)), msg);
        f.render_widget(
            Paragraph::new("s step n line c cont g goto b brk a bar u back w warp ] CTA 1-3 x q")
                .style(Style::new().add_modifier(Modifier::DIM)),
            keys,
        );
        if self.help {
            let area = centered(f.area(), 64, 20);
            f.render_widget(Clear, area);
            f.render_widget(
                Paragraph::new(HELP).block(Block::default().borders(Borders::ALL).title(" keys (any key closes) ")),
                area,
            );
        }
    }

    fn draw_source(&self, f: &mut Frame, area: Rect, st: &Stepper, w: Option<&WarpView>) {
        // compiler-generated instructions (line 0) show the line the warp was last on
        let loc = w.and_then(|w| w.next_source).filter(|s| s.line > 0).or_else(|| {
            let (ev, _) = self.last.get(&self.sel)?;
            let func = st.module().prog.functions.iter().find(|x| x.name == ev.function)?;
            func.info[ev.pc as usize].src
        });
        let prog = &st.module().prog;
        let (title, lines, cur) = match loc {
            Some(s) => {
                let name = prog.files.get(s.file as usize).map(|p| p.rsplit('/').next().unwrap_or(p).to_string());
                match self.sources.get(s.file as usize).and_then(|x| x.as_ref()) {
                    Some(text) => (name.unwrap_or_default(), text.as_slice(), s.line as usize),
                    None => (format!("{} (not found)", name.unwrap_or_default()), &[][..], 0),
                }
            }
            None => ("source (no line info)".to_string(), &[][..], 0),
        };
        let body = window(lines, cur, area, false, |n| if n == cur { ('>', reversed()) } else { (' ', Style::new()) });
        f.render_widget(Paragraph::new(body).block(Block::default().borders(Borders::ALL).title(title)), area);
    }

    fn draw_ptx(&self, f: &mut Frame, area: Rect, st: &Stepper, w: Option<&WarpView>) {
        let prog = &st.module().prog;
        let cur = self.fault_line.or_else(|| w.and_then(|w| w.next_ptx_line)).unwrap_or(0) as usize;
        let body = window(&prog.ptx_lines, cur, area, true, |n| {
            if n == cur {
                ('>', reversed())
            } else if self.o.breaks.ptx.contains(&(n as u32)) {
                ('*', Style::new().fg(Color::Red))
            } else {
                (' ', Style::new())
            }
        });
        let title = format!("PTX {}", w.map(|w| w.function.as_str()).unwrap_or("(finished)"));
        f.render_widget(Paragraph::new(body).block(Block::default().borders(Borders::ALL).title(title)), area);
    }

    fn draw_stack(&self, f: &mut Frame, area: Rect, st: &Stepper, w: Option<&WarpView>) {
        let mut lines = Vec::new();
        match w {
            None => lines.push(Line::raw("no such warp (the CTA may have finished)")),
            Some(w) => {
                let prog = &st.module().prog;
                let func = prog.functions.iter().find(|x| x.name == w.function);
                let line_of = |pc: u32| {
                    func.and_then(|f| f.info.get(pc as usize))
                        .map(|i| format!("L{}", i.ptx_line))
                        .unwrap_or("end".into())
                };
                lines.push(Line::raw(format!(
                    "{:?}  live {:08x}  call depth {}  in {}",
                    w.state, w.live, w.call_depth, w.function
                )));
                for (i, e) in w.stack.iter().enumerate().rev() {
                    let rpc =
                        if e.rpc == u32::MAX { "exit".to_string() } else { format!("{} {}", e.rpc, line_of(e.rpc)) };
                    let top = if i + 1 == w.stack.len() { " <- running" } else { "" };
                    lines.push(Line::raw(format!(
                        " stack[{i}] pc {} {:<6} rpc {rpc:<10} mask {:08x} ({:>2}){top}",
                        e.pc,
                        line_of(e.pc),
                        e.mask,
                        e.mask.count_ones()
                    )));
                }
            }
        }
        let mut warps = Vec::new();
        for k in 0..st.warps_per_cta() as u32 {
            if let Some(v) = st.warp(self.sel.0, k) {
                let at = v.next_ptx_line.map(|l| format!("L{l}")).unwrap_or("done".into());
                let s = format!("w{k} {at} {:>2}/32", v.active.count_ones());
                warps.push(if k == self.sel.1 { format!("[{s}]") } else { format!(" {s} ") });
            }
        }
        let room = area.height.saturating_sub(2) as usize;
        let keep = room.saturating_sub(warps.len().div_ceil(4)).max(1);
        lines.truncate(keep);
        for row in warps.chunks(4) {
            lines.push(Line::styled(row.join(""), Style::new().fg(Color::Cyan)));
        }
        f.render_widget(
            Paragraph::new(lines)
                .block(Block::default().borders(Borders::ALL).title(" 1 SIMT stack | 2 regs | 3 memory ")),
            area,
        );
    }

    fn draw_registers(&self, f: &mut Frame, area: Rect, st: &Stepper, w: Option<&WarpView>) {
        let mut names: Vec<String> = self.o.watches.clone();
        for n in st.register_names(self.sel.0, self.sel.1) {
            if !names.contains(&n) {
                names.push(n);
            }
        }
        let active = w.map(|w| w.active).unwrap_or(0);
        let mut lines = Vec::new();
        let first = self.reg_first.min(names.len().saturating_sub(1));
        for name in names.iter().skip(first).take(2) {
            let Some(v) = st.register(self.sel.0, self.sel.1, name) else {
                lines.push(Line::raw(format!("{name}: no such register here")));
                continue;
            };
            lines.push(Line::styled(name.clone(), Style::new().add_modifier(Modifier::BOLD)));
            for row in 0..4 {
                let spans: Vec<Span> = (row * 8..row * 8 + 8)
                    .map(|l| {
                        let s = format!("{:>9}", self.format_value(v[l]));
                        if active >> l & 1 != 0 {
                            Span::raw(s)
                        } else {
                            Span::styled(s, Style::new().fg(Color::DarkGray))
                        }
                    })
                    .collect();
                let mut all = vec![Span::raw(format!("{:>3}", row * 8))];
                all.extend(spans);
                lines.push(Line::from(all));
            }
        }
        let title = format!(
            " 2 registers {}-{} of {} (j/k scroll, x {}) ",
            first + 1,
            (first + 2).min(names.len()),
            names.len(),
            match self.radix {
                Radix::Dec => "dec",
                Radix::Hex => "hex",
                Radix::Float => "f32",
            }
        );
        f.render_widget(Paragraph::new(lines).block(Block::default().borders(Borders::ALL).title(title)), area);
    }

    fn format_value(&self, v: u64) -> String {
        let s = match self.radix {
            Radix::Dec => (v as i64).to_string(),
            Radix::Hex => format!("{v:x}"),
            Radix::Float => {
                let x = f32::from_bits(v as u32);
                if x.abs() >= 1e5 || (x != 0.0 && x.abs() < 1e-3) { format!("{x:.2e}") } else { format!("{x:.4}") }
            }
        };
        if s.len() > 8 { format!("{}~", &s[..7]) } else { s }
    }

    fn draw_memory(&self, f: &mut Frame, area: Rect, st: &Stepper) {
        let mut lines = Vec::new();
        match self.last_mem.get(&self.sel) {
            None => lines.push(Line::raw("this warp has not run a memory instruction yet")),
            Some((ev, accesses)) => {
                let prog = &st.module().prog;
                let text = prog.ptx_lines.get(ev.ptx_line as usize - 1).map(|s| s.trim().replace('\t', " "));
                lines.push(Line::raw(format!("PTX {}: {}", ev.ptx_line, text.unwrap_or_default())));
                for a in accesses {
                    let e = explain::explain(self.o.profile, a);
                    lines.push(Line::styled(e.summary.clone(), Style::new().fg(Color::Green)));
                    let base = (0..32).filter(|l| a.mask >> l & 1 != 0).map(|l| a.addrs[l]).min().unwrap_or(0);
                    let unit = if a.space == crate::ptx::ir::MemSpace::Shared { "bank" } else { "unit" };
                    lines.push(Line::raw(format!("lanes: +offset from {base:#x} / {unit} of each lane")));
                    for row in 0..4 {
                        let mut s = format!("{:>2}-{:<2} ", row * 8, row * 8 + 7);
                        for l in row * 8..row * 8 + 8 {
                            let cell = match e.lane_unit[l] {
                                Some(u) => format!("+{:x}/{u}", a.addrs[l] - base),
                                None => "-".into(),
                            };
                            s.push_str(&format!("{cell:>8} "));
                        }
                        lines.push(Line::raw(s));
                    }
                    let units: Vec<String> = e
                        .units
                        .iter()
                        .enumerate()
                        .filter(|(_, u)| u.lanes != 0)
                        .map(|(i, u)| format!("{i}={}", u.label))
                        .collect();
                    lines.push(Line::raw(units.join("  ")));
                }
            }
        }
        f.render_widget(
            Paragraph::new(lines).block(Block::default().borders(Borders::ALL).title(" 3 last memory instruction ")),
            area,
        );
    }
}

/// What a key asks to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Action {
    Instruction,
    SourceLine,
    Continue,
    Barrier,
    Goto(u32),
}

/// The 32-lane strip: `#` running, `.` waiting on another path, ` ` exited.
fn mask_line(w: Option<&WarpView>) -> Line<'static> {
    let Some(w) = w else { return Line::raw("lanes: (no warp)") };
    let mut spans = vec![Span::raw("lanes 0-31 ")];
    for l in 0..32 {
        let (c, style) = if w.active >> l & 1 != 0 {
            ("#", Style::new().fg(Color::Green))
        } else if w.live >> l & 1 != 0 {
            (".", Style::new().fg(Color::Yellow))
        } else {
            (" ", Style::new())
        };
        spans.push(Span::styled(c, style));
    }
    spans.push(Span::raw(format!(" active {:08x} ({})", w.active, w.active.count_ones())));
    Line::from(spans)
}

fn reversed() -> Style {
    Style::new().add_modifier(Modifier::REVERSED)
}

/// The lines of a listing that fit `area` (inside its border), centred on line
/// `cur` (1-based), each numbered, with the mark and style `mark(n)` gives.
/// `trim` drops leading whitespace (PTX indents with tabs).
fn window(
    lines: &[String],
    cur: usize,
    area: Rect,
    trim: bool,
    mark: impl Fn(usize) -> (char, Style),
) -> Vec<Line<'static>> {
    let inner = area.height.saturating_sub(2) as usize;
    let first = cur.saturating_sub(inner / 2 + 1);
    lines
        .iter()
        .enumerate()
        .skip(first)
        .take(inner)
        .map(|(i, l)| {
            let n = i + 1;
            let (m, style) = mark(n);
            let text = if trim { l.trim().replace('\t', " ") } else { l.trim_end().replace('\t', "    ") };
            Line::styled(format!("{m}{n:>4} {text}"), style)
        })
        .collect()
}

fn centered(r: Rect, w: u16, h: u16) -> Rect {
    let w = w.min(r.width);
    let h = h.min(r.height);
    Rect { x: r.x + (r.width - w) / 2, y: r.y + (r.height - h) / 2, width: w, height: h }
}

const HELP: &str = "\
s, space   step: run until the selected warp issues one instruction
n          step a source line (until the warp leaves its CUDA line)
c          continue until any warp reaches a breakpoint
g N Enter  run the selected warp to PTX line N
b N Enter  toggle a breakpoint at PTX line N (empty: current line)
a          continue until the selected warp reaches a barrier
u, <-      step back (undo the last action by replaying)
w / W      next / previous warp of the CTA  (Tab / Shift-Tab)
] / [      next / previous resident CTA
1 2 3      panel: SIMT stack, registers, memory (also m)
x          registers in decimal, hex or f32
j / k      scroll the registers
q, Esc     quit

Lanes: # running, . waiting on another path, blank exited.
Memory units are the transactions, sectors or banks the lanes'
addresses form under the device profile (--device).";
