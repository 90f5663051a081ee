//! The interactive terminal view of `warplight step`: CUDA source and PTX at
//! the selected warp's next instruction (side by side from 100 columns, one
//! pane with `v` to switch below that), its 32-lane active mask, and below one
//! of four panels — the SIMT reconvergence stack (with the CTA's warps),
//! per-lane register values, the last memory instruction's per-lane addresses
//! with the transactions, sectors or banks they form under the chosen device
//! profile, memory contents (the CTA's shared variables and the spec's
//! buffers by name), or the kernel's `printf` output so far, each line with
//! the step that printed it (the message line tells when a step printed).
//! Fits an 80×24 terminal.
//!
//! The source pane stays on the user's file: lines of library headers and the
//! compiler's line 0 show the user's line they belong to (see
//! [`super::user_lines`]).
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
use super::printed::{self, Printed};
use super::session::{Buffers, Error, Session};
use super::sources;
use super::track::{Effect, Tracker};
use super::user_lines;
use crate::model::Profile;
use crate::model::explain;
use crate::ptx::ir::SrcLoc;
use crate::sim::access_log::Access;
use crate::sim::stepper::{StepEvent, Stepper, WarpView};

/// From this width on, source and PTX are shown side by side.
pub const WIDE: u16 = 100;

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
        let exit = session.with_stepping(|st, bufs, out| {
            app.replay(st, out, target)?;
            loop {
                terminal.draw(|f| app.draw(f, st, bufs))?;
                let Some(key) = next_key()? else { return Ok(Exit::Quit) };
                match app.handle(key, st, out)? {
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
    /// Memory contents: shared variables and the spec's buffers.
    Data,
    /// The `printf` output so far, by step.
    Output,
}

/// The code pane shown below [`WIDE`] columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CodePane {
    /// The CUDA source.
    Source,
    /// The PTX.
    Ptx,
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
    /// First lane of the register panel's columns.
    lane_first: usize,
    /// The code pane shown in narrow terminals.
    pub code: CodePane,
    /// Columns the code panes are scrolled right by.
    hscroll: usize,
    /// The region of the memory-contents panel and its first row.
    data_region: usize,
    data_first: usize,
    /// The `printf` output up to the current step: (step, labelled line).
    printed: Vec<(u64, String)>,
    /// Lines the output panel is scrolled back from its end.
    out_back: usize,
    /// [`user_lines::attribute`] of the program.
    user: Vec<Vec<Option<SrcLoc>>>,
    /// Each warp's last user source line.
    last_user: HashMap<(usize, u32), SrcLoc>,
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
        let (sources, user) = session.with_stepper(|st| {
            let prog = &st.module().prog;
            Ok((sources::read_all(prog, &session.ptx_path()), user_lines::attribute(prog)))
        })?;
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
            lane_first: 0,
            code: CodePane::Source,
            hscroll: 0,
            data_region: 0,
            data_first: 0,
            printed: Vec::new(),
            out_back: 0,
            user,
            last_user: HashMap::new(),
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
    fn replay(&mut self, st: &mut Stepper, out: &Printed, target: u64) -> Result<(), Error> {
        self.steps = 0;
        self.printed.clear();
        self.fault = None;
        self.fault_line = None;
        self.last.clear();
        self.last_mem.clear();
        self.last_user.clear();
        self.tracker = Tracker::default();
        while self.steps < target {
            if self.step_one(st, out)?.is_none() {
                break;
            }
        }
        Ok(())
    }

    /// Issues one warp instruction (any warp, in scheduling order).
    fn step_one(&mut self, st: &mut Stepper, out: &Printed) -> Result<Option<(StepEvent, WarpView)>, Error> {
        let Some(ev) = st.step()? else { return Ok(None) };
        self.steps += 1;
        let step = self.steps;
        self.printed.extend(printed::labelled(&out.take()).into_iter().map(|l| (step, l)));
        let key = (ev.cta_slot, ev.warp);
        let w = st.warp(ev.cta_slot, ev.warp).ok_or("stepped warp vanished")?;
        let fx = self.tracker.observe(&ev, &w);
        if let Some(u) = self.user_at(st, &ev.function, Some(ev.pc)) {
            self.last_user.insert(key, u);
        }
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
        out: &Printed,
        mut stop: impl FnMut(&Self, &Stepper, &StepEvent, &WarpView) -> bool,
    ) -> Result<Option<StepEvent>, Error> {
        for _ in 0..self.o.max_steps {
            match self.step_one(st, out)? {
                None => {
                    self.message = format!("the grid finished after {} warp instructions", self.steps);
                    return Ok(None);
                }
                Some((ev, w)) => {
                    if stop(self, st, &ev, &w) {
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

    /// The user source line of instruction `pc` of `function` (a line > 0 of
    /// the user's file: library code counts as its calling line).
    fn user_at(&self, st: &Stepper, function: &str, pc: Option<u32>) -> Option<SrcLoc> {
        let prog = &st.module().prog;
        let f = prog.functions.iter().position(|x| x.name == function)?;
        let loc = (*self.user.get(f)?.get(pc? as usize)?)?;
        user_lines::user_loc(prog, Some(loc))
    }

    /// The user source line the view shows for warp `key` in state `w`: that
    /// of its next instruction, else (compiler-generated code) the last user
    /// line it ran.
    fn shown_line(&self, st: &Stepper, key: (usize, u32), w: &WarpView) -> Option<SrcLoc> {
        self.user_at(st, &w.function, w.next_pc).or_else(|| self.last_user.get(&key).copied())
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

    fn handle(&mut self, key: KeyEvent, st: &mut Stepper, out: &Printed) -> Result<Exit, Error> {
        if self.help {
            self.help = false;
            return Ok(Exit::Stay);
        }
        if let Some(p) = self.prompt.take() {
            return self.handle_prompt(p, key, st, out);
        }
        let ctrl = key.modifiers.contains(KeyModifiers::CONTROL);
        match key.code {
            KeyCode::Char('q') | KeyCode::Esc => return Ok(Exit::Quit),
            KeyCode::Char('c') if ctrl => return Ok(Exit::Quit),
            KeyCode::Char('?') | KeyCode::F(1) => self.help = true,
            KeyCode::Char('s') | KeyCode::Char(' ') | KeyCode::Down => self.act(st, out, Action::Instruction)?,
            KeyCode::Char('n') => self.act(st, out, Action::SourceLine)?,
            KeyCode::Char('c') => self.act(st, out, Action::Continue)?,
            KeyCode::Char('a') => self.act(st, out, Action::Barrier)?,
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
            KeyCode::Char('4') => self.panel = Panel::Data,
            KeyCode::Char('5') => {
                self.panel = Panel::Output;
                self.out_back = 0;
            }
            KeyCode::Char('v') => {
                self.code = match self.code {
                    CodePane::Source => CodePane::Ptx,
                    CodePane::Ptx => CodePane::Source,
                }
            }
            KeyCode::Char('>') | KeyCode::Right => self.hscroll += 8,
            KeyCode::Char('<') => self.hscroll = self.hscroll.saturating_sub(8),
            KeyCode::Char('l') => self.lane_first = (self.lane_first + 8) % 32,
            KeyCode::Char('o') => {
                self.data_region += 1;
                self.data_first = 0;
            }
            KeyCode::Char('x') => {
                self.radix = match self.radix {
                    Radix::Dec => Radix::Hex,
                    Radix::Hex => Radix::Float,
                    Radix::Float => Radix::Dec,
                }
            }
            KeyCode::Char('j') | KeyCode::PageDown if self.panel == Panel::Data => self.data_first += 1,
            KeyCode::Char('j') | KeyCode::PageDown if self.panel == Panel::Output => {
                self.out_back = self.out_back.saturating_sub(1)
            }
            KeyCode::Char('k') | KeyCode::PageUp | KeyCode::Up if self.panel == Panel::Output => self.out_back += 1,
            KeyCode::Char('k') | KeyCode::PageUp | KeyCode::Up if self.panel == Panel::Data => {
                self.data_first = self.data_first.saturating_sub(1)
            }
            KeyCode::Char('j') | KeyCode::PageDown => self.reg_first += 1,
            KeyCode::Char('k') | KeyCode::PageUp | KeyCode::Up => self.reg_first = self.reg_first.saturating_sub(1),
            _ => {}
        }
        Ok(Exit::Stay)
    }

    fn handle_prompt(&mut self, p: Prompt, key: KeyEvent, st: &mut Stepper, out: &Printed) -> Result<Exit, Error> {
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
                    self.act(st, out, Action::Goto(line))?;
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

    fn act(&mut self, st: &mut Stepper, out: &Printed, a: Action) -> Result<(), Error> {
        let printed_before = self.printed.len();
        self.act_on(st, out, a)?;
        // what the action printed, on the message line (the panel 5 lists it)
        let n = self.printed.len() - printed_before;
        if n > 0 {
            self.out_back = 0;
            let last = &self.printed[self.printed.len() - 1].1;
            self.message = if n == 1 {
                format!("{}; printf: {last}", self.message)
            } else {
                format!("{}; printf: {n} lines, the last {last} (5 lists them)", self.message)
            };
        }
        Ok(())
    }

    fn act_on(&mut self, st: &mut Stepper, out: &Printed, a: Action) -> Result<(), Error> {
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
        let start_line = self.shown_line(st, sel, &w0);
        let is_sel = move |ev: &StepEvent| (ev.cta_slot, ev.warp) == sel;
        let result = match a {
            Action::Instruction => self.run_until(st, out, |_, _, ev, _| is_sel(ev)),
            // the next source line, or a change of the warp's lanes (divergence,
            // reconvergence, a switch to the waiting path), whichever comes first
            Action::SourceLine => self.run_until(st, out, |app, st, ev, w| {
                if !is_sel(ev) {
                    return false;
                }
                let fx = app.last.get(&sel).map(|x| x.1).unwrap_or_default();
                let line = app.shown_line(st, sel, w);
                w.next_pc.is_none() || fx.diverged || fx.reconverged || fx.switched || line != start_line
            }),
            Action::Goto(l) => self.run_until(st, out, |_, _, ev, w| is_sel(ev) && w.next_ptx_line == Some(l)),
            Action::Barrier => self.run_until(st, out, |_, _, ev, _| is_sel(ev) && ev.opcode.starts_with("bar")),
            Action::Continue => self.run_until(st, out, |app, _, ev, w| app.o.breaks.hit(ev, w).is_some()),
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
    pub fn draw(&self, f: &mut Frame, st: &Stepper, bufs: &Buffers) {
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
        if panes.width >= WIDE {
            let [left, right] =
                Layout::horizontal([Constraint::Percentage(50), Constraint::Percentage(50)]).areas(panes);
            self.draw_source(f, left, st, w.as_ref(), false);
            self.draw_ptx(f, right, st, w.as_ref(), false);
        } else {
            match self.code {
                CodePane::Source => self.draw_source(f, panes, st, w.as_ref(), true),
                CodePane::Ptx => self.draw_ptx(f, panes, st, w.as_ref(), true),
            }
        }
        f.render_widget(Paragraph::new(mask_line(w.as_ref())), mask);
        match self.panel {
            Panel::Stack => self.draw_stack(f, lower, st, w.as_ref()),
            Panel::Registers => self.draw_registers(f, lower, st, w.as_ref()),
            Panel::Memory => self.draw_memory(f, lower, st),
            Panel::Data => self.draw_data(f, lower, st, bufs),
            Panel::Output => self.draw_output(f, lower),
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
            Paragraph::new("s step n line c cont g goto b brk a bar u back w warp v pane 1-5 panel ? help q")
                .style(Style::new().add_modifier(Modifier::DIM)),
            keys,
        );
        if self.help {
            let lines = HELP.lines().count() as u16 + 2;
            let width = HELP.lines().map(|l| l.chars().count()).max().unwrap_or(0) as u16 + 2;
            let area = centered(f.area(), width, lines);
            f.render_widget(Clear, area);
            f.render_widget(
                Paragraph::new(HELP).block(Block::default().borders(Borders::ALL).title(" keys (any key closes) ")),
                area,
            );
        }
    }

    fn draw_source(&self, f: &mut Frame, area: Rect, st: &Stepper, w: Option<&WarpView>, single: bool) {
        // the user's line: library code shows its calling line, compiler-generated
        // instructions (line 0) the line the warp was last on
        let loc = w.and_then(|w| self.shown_line(st, self.sel, w));
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
        let body = window(lines, cur, area, false, self.hscroll, |n| {
            if n == cur { ('>', reversed()) } else { (' ', Style::new()) }
        });
        let mut block = Block::default().borders(Borders::ALL).title(format!(" {title} "));
        if single {
            // the PTX instruction about to run, under the source
            let line = self.fault_line.or_else(|| w.and_then(|w| w.next_ptx_line)).unwrap_or(0);
            let text = prog.ptx_lines.get((line as usize).wrapping_sub(1)).map(|s| s.trim().replace('\t', " "));
            block = block
                .title(Line::raw(" v: PTX ").right_aligned())
                .title_bottom(format!(" PTX {line}: {} ", text.unwrap_or_default()));
        }
        f.render_widget(Paragraph::new(body).block(block), area);
    }

    fn draw_ptx(&self, f: &mut Frame, area: Rect, st: &Stepper, w: Option<&WarpView>, single: bool) {
        let prog = &st.module().prog;
        let cur = self.fault_line.or_else(|| w.and_then(|w| w.next_ptx_line)).unwrap_or(0) as usize;
        let body = window(&prog.ptx_lines, cur, area, true, self.hscroll, |n| {
            if n == cur {
                ('>', reversed())
            } else if self.o.breaks.ptx.contains(&(n as u32)) {
                ('*', Style::new().fg(Color::Red))
            } else {
                (' ', Style::new())
            }
        });
        let title = format!(" PTX {} ", w.map(|w| w.function.as_str()).unwrap_or("(finished)"));
        let mut block = Block::default().borders(Borders::ALL).title(title);
        if single {
            let src = w.and_then(|w| self.shown_line(st, self.sel, w)).map(|s| {
                let text = self
                    .sources
                    .get(s.file as usize)
                    .and_then(|x| x.as_ref())
                    .and_then(|t| t.get(s.line as usize - 1))
                    .map(|t| t.trim().to_string())
                    .unwrap_or_default();
                format!(" line {}: {text} ", s.line)
            });
            block = block.title(Line::raw(" v: source ").right_aligned()).title_bottom(src.unwrap_or_default());
        }
        f.render_widget(Paragraph::new(body).block(block), area);
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
        let prog = &st.module().prog;
        let func = w.and_then(|w| prog.functions.iter().find(|x| x.name == w.function));
        // width of a register in bits (predicates: 1)
        let bits = |name: &str| {
            func.and_then(|f| f.reg_names.iter().position(|n| n == name).map(|i| f.reg_masks[i].count_ones()))
                .unwrap_or(1)
        };
        // one row a register, one column a lane: as many lanes as fit, 8 at least
        let inner = area.width.saturating_sub(2) as usize;
        const NAME: usize = 6;
        const CELL: usize = 9;
        let lanes = match inner.saturating_sub(NAME) / CELL {
            n if n >= 32 => 32,
            n if n >= 16 => 16,
            _ => 8,
        };
        let lane0 = if lanes == 32 { 0 } else { self.lane_first / lanes * lanes };
        let rows = area.height.saturating_sub(3) as usize;
        let first = self.reg_first.min(names.len().saturating_sub(1));
        let mut lines = vec![Line::styled(
            format!("{:<NAME$}{}", "lane", (lane0..lane0 + lanes).map(|l| format!("{l:>CELL$}")).collect::<String>()),
            Style::new().add_modifier(Modifier::BOLD),
        )];
        for name in names.iter().skip(first).take(rows) {
            let Some(v) = st.register(self.sel.0, self.sel.1, name) else {
                lines.push(Line::raw(format!("{name}: no such register here")));
                continue;
            };
            let b = bits(name);
            let mut spans = vec![Span::styled(format!("{name:<NAME$}"), Style::new().add_modifier(Modifier::BOLD))];
            for (l, &x) in v.iter().enumerate().skip(lane0).take(lanes) {
                let s = format!("{:>CELL$}", self.format_value(x, b));
                spans.push(if active >> l & 1 != 0 {
                    Span::raw(s)
                } else {
                    Span::styled(s, Style::new().fg(Color::DarkGray))
                });
            }
            lines.push(Line::from(spans));
        }
        let last = (first + rows).min(names.len());
        let title = format!(
            " 2 registers {}-{last} of {} (j/k, l lanes, x {}) ",
            first + 1,
            names.len(),
            match self.radix {
                Radix::Dec => "dec",
                Radix::Hex => "hex",
                Radix::Float => "float",
            }
        );
        f.render_widget(Paragraph::new(lines).block(Block::default().borders(Borders::ALL).title(title)), area);
    }

    /// A register value of `bits` bits in the chosen radix, at most 8 characters:
    /// decimal is signed (two's complement of the register's width), float reads
    /// 32-bit registers as f32 and 64-bit ones as f64.
    fn format_value(&self, v: u64, bits: u32) -> String {
        let s = match self.radix {
            Radix::Dec => signed(v, bits).to_string(),
            Radix::Hex => format!("{v:x}"),
            Radix::Float => {
                let x = if bits == 64 { f64::from_bits(v) } else { f32::from_bits(v as u32) as f64 };
                if x.abs() >= 1e5 || (x != 0.0 && x.abs() < 1e-3) { format!("{x:.2e}") } else { format!("{x:.4}") }
            }
        };
        if s.chars().count() > 8 { format!("{}~", &s[..7]) } else { s }
    }

    fn draw_data(&self, f: &mut Frame, area: Rect, st: &Stepper, bufs: &Buffers) {
        let regions = data_regions(st, &self.kernel, self.sel.0, bufs);
        let mut lines = Vec::new();
        let title;
        if regions.is_empty() {
            title = " 4 memory: no shared variables or buffers ".to_string();
        } else {
            let r = &regions[self.data_region % regions.len()];
            let names: Vec<String> = regions
                .iter()
                .enumerate()
                .map(
                    |(i, x)| {
                        if i == self.data_region % regions.len() { format!("[{}]", x.name) } else { x.name.clone() }
                    },
                )
                .collect();
            title = format!(" 4 memory {} (o next, j/k) ", r.kind);
            lines.push(Line::styled(names.join(" "), Style::new().fg(Color::Cyan)));
            let inner = area.width.saturating_sub(2) as usize;
            let cell = 9usize;
            let per_row = if inner >= 6 + 16 * cell { 16 } else { 8 };
            let rows = area.height.saturating_sub(3) as usize;
            let first = self.data_first.min(r.len.saturating_sub(1) / per_row) * per_row;
            let values = match &r.source {
                DataSource::Shared { offset } => st.shared(self.sel.0).map(|sh| {
                    let start = (*offset + first * 4).min(sh.len());
                    let end = (start + rows * per_row * 4).min(*offset + r.len * 4).min(sh.len());
                    sh[start..end].chunks(4).map(|c| self.format_word(c)).collect::<Vec<_>>()
                }),
                DataSource::Buffer => bufs.read(&r.name, first, rows * per_row).map(|(ty, bytes)| {
                    bytes
                        .chunks(ty.size())
                        .map(|c| if self.radix == Radix::Hex { hex(c) } else { ty.show(c) })
                        .map(|s| if s.chars().count() > 8 { format!("{}~", &s[..7]) } else { s })
                        .collect()
                }),
            };
            let values = values.unwrap_or_default();
            for (i, row) in values.chunks(per_row).enumerate() {
                let mut s = format!("{:>5} ", first + i * per_row);
                for v in row {
                    s.push_str(&format!("{v:>8} "));
                }
                lines.push(Line::raw(s));
            }
            if values.is_empty() {
                lines.push(Line::raw("(empty)"));
            }
        }
        f.render_widget(Paragraph::new(lines).block(Block::default().borders(Borders::ALL).title(title)), area);
    }

    /// A 4-byte shared-memory word in the chosen radix (decimal: signed 32-bit).
    fn format_word(&self, c: &[u8]) -> String {
        let mut w = [0u8; 4];
        w[..c.len()].copy_from_slice(c);
        self.format_value(u32::from_le_bytes(w) as u64, 32)
    }

    /// The `printf` output so far, one line a lane's line with the step that
    /// printed it; the last step's lines in green. Scrolled to the end unless
    /// `k` moved it back.
    fn draw_output(&self, f: &mut Frame, area: Rect) {
        let rows = area.height.saturating_sub(2) as usize;
        let end = self.printed.len().saturating_sub(self.out_back.min(self.printed.len().saturating_sub(rows)));
        let first = end.saturating_sub(rows);
        let mut lines: Vec<Line> = self.printed[first..end]
            .iter()
            .map(|(step, l)| {
                let text = format!("{step:>6} {}", l.replace('\t', "    "));
                if *step == self.steps { Line::styled(text, Style::new().fg(Color::Green)) } else { Line::raw(text) }
            })
            .collect();
        if lines.is_empty() {
            lines.push(Line::raw("nothing printed yet (printf output appears here at the step that prints it)"));
        }
        let title = format!(" 5 printf output: {} lines to step {} (j/k) ", self.printed.len(), self.steps);
        f.render_widget(Paragraph::new(lines).block(Block::default().borders(Borders::ALL).title(title)), area);
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
/// `cur` (1-based), each numbered, with the mark and style `mark(n)` gives,
/// the text scrolled `hscroll` columns right (the numbers stay). `trim` drops
/// leading whitespace (PTX indents with tabs).
fn window(
    lines: &[String],
    cur: usize,
    area: Rect,
    trim: bool,
    hscroll: usize,
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
            let text: String = text.chars().skip(hscroll).collect();
            Line::styled(format!("{m}{n:>4} {text}"), style)
        })
        .collect()
}

/// `v`'s low `bits` bits as a two's-complement number.
fn signed(v: u64, bits: u32) -> i64 {
    match bits {
        0 | 1 => v as i64 & 1,
        b if b >= 64 => v as i64,
        b => ((v << (64 - b)) as i64) >> (64 - b),
    }
}

/// Little-endian bytes as one hexadecimal number.
fn hex(c: &[u8]) -> String {
    let mut w = [0u8; 8];
    w[..c.len().min(8)].copy_from_slice(&c[..c.len().min(8)]);
    format!("{:x}", u64::from_le_bytes(w))
}

/// Where a region of the memory-contents panel lives.
#[derive(Debug, Clone, PartialEq, Eq)]
enum DataSource {
    /// The CTA's shared memory from this byte offset, as 4-byte words.
    Shared { offset: usize },
    /// A buffer of the spec, by its name.
    Buffer,
}

/// A region of the memory-contents panel.
#[derive(Debug, Clone, PartialEq, Eq)]
struct DataRegion {
    /// Its name: the source name of a shared variable, a buffer's name.
    name: String,
    /// A word for the title.
    kind: String,
    /// Elements.
    len: usize,
    source: DataSource,
}

/// The shared variables `kernel` names, in CTA slot `slot` (by source name,
/// from their mangled PTX names), then the spec's buffers.
fn data_regions(st: &Stepper, kernel: &str, slot: usize, bufs: &Buffers) -> Vec<DataRegion> {
    let prog = &st.module().prog;
    let shared_len = st.shared(slot).map(|s| s.len()).unwrap_or(0);
    let refs = prog.functions.iter().find(|f| f.name == kernel).map(|f| f.shared_refs.clone()).unwrap_or_default();
    let mut v: Vec<DataRegion> = prog
        .shared_vars
        .iter()
        .filter(|s| refs.is_empty() || refs.contains(&s.offset))
        .map(|s| {
            let bytes = if s.size == 0 { shared_len.saturating_sub(s.offset as usize) } else { s.size as usize };
            DataRegion {
                name: source_name(&s.name),
                kind: format!("shared {} ({bytes} B at {:#x}, 4-byte words)", s.name, s.offset),
                len: bytes / 4,
                source: DataSource::Shared { offset: s.offset as usize },
            }
        })
        .filter(|r| r.len > 0)
        .collect();
    for b in bufs.specs() {
        v.push(DataRegion {
            name: b.name.clone(),
            kind: format!("buffer {} ({} x {:?})", b.name, b.len, b.ty).to_lowercase(),
            len: b.len,
            source: DataSource::Buffer,
        });
    }
    v
}

/// The source name of a PTX variable: a function-local static's mangled name
/// `_ZZ<n>funcE<n>name` (as clang and nvcc write `__shared__` arrays declared
/// in a kernel) becomes `func::name`; other names stay as they are.
pub fn source_name(ptx: &str) -> String {
    fn part(s: &str) -> Option<(&str, &str)> {
        let digits = s.chars().take_while(|c| c.is_ascii_digit()).count();
        let n: usize = s[..digits].parse().ok()?;
        let rest = &s[digits..];
        (rest.len() >= n).then(|| rest.split_at(n))
    }
    let Some(rest) = ptx.strip_prefix("_ZZ") else {
        return ptx.to_string();
    };
    let Some((func, rest)) = part(rest) else { return ptx.to_string() };
    // a C++ function's parameter types follow its name up to `E`
    let Some((_, rest)) = rest.split_once('E') else { return ptx.to_string() };
    match part(rest) {
        Some((name, _)) => format!("{func}::{name}"),
        None => ptx.to_string(),
    }
}

fn centered(r: Rect, w: u16, h: u16) -> Rect {
    let w = w.min(r.width);
    let h = h.min(r.height);
    Rect { x: r.x + (r.width - w) / 2, y: r.y + (r.height - h) / 2, width: w, height: h }
}

const HELP: &str = "\
s, space  step: run until the selected warp issues one instruction
n         next line: until the warp leaves its CUDA line, diverges or
          reconverges
c         continue until any warp reaches a breakpoint
g N Enter run the selected warp to PTX line N
b N Enter toggle a breakpoint at PTX line N (empty: current line)
a         continue until the selected warp reaches a barrier
u, <-     step back (undo the last action by replaying)
w W Tab   next / previous warp of the CTA;  ] [  next / previous CTA
v         source or PTX (narrow terminals);  > <  scroll code sideways
1 ... 5   panel: SIMT stack, registers, last memory access, memory,
          printf output (each line with the step that printed it)
x         decimal (signed), hex or float;  j k  scroll;  l  more lanes
o         memory panel: next shared variable or buffer
q, Esc    quit
Lanes: # running, . waiting on another path, blank exited.";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_is_signed_in_the_register_width() {
        assert_eq!(signed(0xffff_ffff, 32), -1);
        assert_eq!(signed(0x7fff_ffff, 32), i32::MAX as i64);
        assert_eq!(signed(0xffff, 16), -1);
        assert_eq!(signed(u64::MAX, 64), -1);
        assert_eq!(signed(1, 1), 1);
        assert_eq!(hex(&[0x34, 0x12]), "1234");
    }

    #[test]
    fn shared_variables_get_their_source_names() {
        assert_eq!(source_name("_ZZ10reduce_sumE1s"), "reduce_sum::s");
        assert_eq!(source_name("_ZZ6reduceiE4part"), "reduce::part");
        assert_eq!(source_name("buf"), "buf");
        assert_eq!(source_name("_ZZ99x"), "_ZZ99x");
    }
}
