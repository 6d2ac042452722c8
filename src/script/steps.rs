//! Part of stage 4 (decision): an `on_tick()` of a few statements evaluated natively.
//!
//! A species' `on_tick()` often keeps a little bookkeeping on the blackboard, as the sardine's
//! running mean of its speed:
//!
//! ```rhai
//! let prev = if this.has("mean_speed") { this["mean_speed"] } else { () };
//! this["mean_speed"] = school::running_mean(prev, this.speed, elapsed, 2.0);
//! ```
//!
//! Through the interpreter that call costs about 3.6 µs. Evaluated here it costs a few
//! hundred nanoseconds at most. The statements taken: `let x = e;`, `x = e;`, `this["k"] = e;`
//! (a key the species declares as a bool, int or float), `if c { … } else { … }` (as a
//! statement or a value), `return e;` and expression statements; the expressions of
//! [`super::native`] plus `()`, local variables, `type_of(e) == "name"` (or `!=`) and calls of
//! functions of the same forms, the script's own or an imported module's, arguments first, left
//! to right. Anything else leaves the function with the interpreter.
//!
//! Values are typed as they are met (a variable may hold `()` in one call and a number in the
//! next). An operation the interpreter would answer otherwise than these rules (an operand
//! that is `()` or of a type the operator does not take, an integer overflow, a write of
//! another type than the declared one, a full blackboard) hands the whole call back to the
//! interpreter, which gives its own answer or error. Writes are held until the function ends
//! (reads see them), so a call handed back has changed nothing: the interpreter starts afresh.

use super::memory::{MemType, MemorySpec};
use super::native::{
    arith, body_of, callee, checked_floats, compare, defines, has_key, property_chain, scalar_key,
    Arith, Cmp, HandBack, Modules, Prop, Val,
};
use super::view::AgentView;
use crate::world::{MemValue, MEMORY_CAPACITY};
use rhai::{ASTFlags, Dynamic, Expr, ImmutableString, Module, Stmt, AST, FLOAT, INT};
use std::sync::Arc;

/// Local variables a function may hold (more: the interpreter's).
const MAX_SLOTS: usize = 24;

/// Calls nested within one evaluation (deeper: the interpreter's).
const MAX_DEPTH: u8 = 4;

/// A value: `None` is `()`.
type Dv = Option<Val>;

/// A dynamically typed expression.
#[derive(Debug, Clone)]
enum Ex {
    Lit(Dv),
    Prop(Prop),
    Has(Box<str>),
    /// `this["k"]`: `()` when not set.
    Mem(Box<str>),
    Var(u8),
    /// `type_of(e) == name` (`eq`), or `!=`.
    TypeIs(Box<Ex>, &'static str, bool),
    Not(Box<Ex>),
    Neg(Box<Ex>),
    Cmp(Cmp, Box<[Ex; 2]>),
    Arith(Arith, Box<[Ex; 2]>),
    And(Vec<Ex>),
    Or(Vec<Ex>),
    If(Box<Ex>, Block, Block),
    /// Arguments, then the callee's body over them (its parameters its first slots).
    Call(Vec<Ex>, Arc<Block>),
}

#[derive(Debug, Clone, Default)]
struct Block(Vec<St>);

#[derive(Debug, Clone)]
enum St {
    Let(u8, Ex),
    Set(u8, Ex),
    Write(Box<str>, MemType, Ex),
    If(Ex, Block, Block),
    Return(Ex),
    Expr(Ex),
}

/// How a block ended.
enum Flow {
    /// With the value of its last statement.
    Value(Dv),
    /// With `return`.
    Return(Dv),
}

/// A function of statements compiled for native evaluation.
#[derive(Debug, Clone)]
pub struct Steps {
    body: Block,
    spec: Arc<MemorySpec>,
}

impl Steps {
    /// Compiles `name` (without parameters) of `ast` when every statement and expression in
    /// it, and in the functions it calls, is of the forms above; `spec`: the species'
    /// blackboard declaration.
    pub fn compile(
        ast: &AST,
        modules: &Modules,
        spec: &Arc<MemorySpec>,
        name: &str,
    ) -> Option<Steps> {
        if !checked_floats() {
            return None;
        }
        // A function `has(k)` of the script or of a module would take `this.has("k")`.
        let has = defines(ast, modules, "has", 1);
        let f = ast
            .iter_fn_def()
            .find(|f| f.name == name && f.params.is_empty() && f.this_type.is_none())?;
        let mut cx = Cx {
            ast,
            modules,
            spec: (!has).then_some(&**spec),
            top: true,
            module: None,
            depth: 0,
            names: Vec::new(),
            slots: 0,
        };
        let body = cx.block(&body_of(f))?;
        Some(Steps {
            body,
            spec: spec.clone(),
        })
    }

    /// Runs the function for the agent `v`: its blackboard writes land in `v` when it ends.
    /// Handed back, nothing in `v` has changed.
    pub fn run(&self, v: &mut AgentView) -> Result<(), HandBack> {
        let mut env = [None; MAX_SLOTS];
        let mut writes: Vec<(&str, MemValue)> = Vec::new();
        Run {
            v,
            writes: &mut writes,
        }
        .block(&self.body, &mut env)?;
        // A full blackboard refuses a new key: the interpreter raises that error.
        let known = |i: usize, k: &str| {
            v.memory.iter().any(|(m, _)| &**m == k) || writes[..i].iter().any(|(w, _)| *w == k)
        };
        let added = (0..writes.len())
            .filter(|&i| !known(i, writes[i].0))
            .count();
        if v.memory.len() + added > MEMORY_CAPACITY {
            return Err(HandBack);
        }
        for (k, m) in writes {
            super::memory::store(&mut v.memory, k, m, &self.spec).map_err(|_| HandBack)?;
        }
        Ok(())
    }
}

/// Where statements are compiled: the top function (`top`: `this` is the agent) or one it
/// calls (`module`: the module it is in, whose unqualified calls are not followed).
struct Cx<'a> {
    ast: &'a AST,
    modules: &'a Modules,
    spec: Option<&'a MemorySpec>,
    top: bool,
    module: Option<&'a Module>,
    depth: u8,
    /// Variables in scope, innermost last, with their slots.
    names: Vec<(ImmutableString, u8)>,
    slots: usize,
}

impl<'a> Cx<'a> {
    fn slot(&mut self, name: &ImmutableString) -> Option<u8> {
        if self.slots >= MAX_SLOTS {
            return None;
        }
        let k = self.slots as u8;
        self.slots += 1;
        self.names.push((name.clone(), k));
        Some(k)
    }

    fn lookup(&self, name: &str) -> Option<u8> {
        self.names
            .iter()
            .rev()
            .find(|(n, _)| n.as_str() == name)
            .map(|&(_, k)| k)
    }

    /// A block's statements; its variables go out of scope at its end.
    fn block(&mut self, stmts: &[Stmt]) -> Option<Block> {
        let scope = self.names.len();
        let mut out = Vec::with_capacity(stmts.len());
        for s in stmts {
            out.push(self.stmt(s)?);
        }
        self.names.truncate(scope);
        Some(Block(out))
    }

    fn stmt(&mut self, s: &Stmt) -> Option<St> {
        Some(match s {
            Stmt::Var(x, flags, _) if !flags.contains(ASTFlags::EXPORTED) => {
                let value = self.expr(&x.1)?;
                St::Let(self.slot(&x.0.name)?, value)
            }
            Stmt::Assignment(x) => {
                let (op, bin) = &**x;
                if op.is_op_assignment() {
                    return None;
                }
                match &bin.lhs {
                    Expr::Variable(v, _, _) if v.2.is_empty() => {
                        let k = self.lookup(&v.1)?;
                        St::Set(k, self.expr(&bin.rhs)?)
                    }
                    Expr::Index(i, flags, _) if self.top => {
                        let (key, t) = scalar_key(i, *flags, self.spec?)?;
                        St::Write(key.into(), t, self.expr(&bin.rhs)?)
                    }
                    _ => return None,
                }
            }
            Stmt::If(x, _) => {
                let c = self.expr(&x.expr)?;
                let body = self.block(x.body.statements())?;
                let branch = self.block(x.branch.statements())?;
                St::If(c, body, branch)
            }
            Stmt::Return(e, flags, _) if *flags == ASTFlags::NONE => match e {
                Some(e) => St::Return(self.expr(e)?),
                None => St::Return(Ex::Lit(None)),
            },
            Stmt::Expr(e) => St::Expr(self.expr(e)?),
            Stmt::FnCall(call, _) => St::Expr(self.call(call)?),
            _ => return None,
        })
    }

    fn expr(&mut self, e: &Expr) -> Option<Ex> {
        Some(match e {
            Expr::Unit(_) => Ex::Lit(None),
            Expr::BoolConstant(b, _) => Ex::Lit(Some(Val::Bool(*b))),
            Expr::IntegerConstant(i, _) => Ex::Lit(Some(Val::Int(*i))),
            Expr::FloatConstant(f, _) => Ex::Lit(Some(Val::Float(**f))),
            Expr::Variable(v, _, _) if v.2.is_empty() => Ex::Var(self.lookup(&v.1)?),
            Expr::Dot(x, _, _) if self.top => {
                if let (Expr::ThisPtr(_), Expr::MethodCall(call, _)) = (&x.lhs, &x.rhs) {
                    return Some(Ex::Has(has_key(call, self.spec?)?.into()));
                }
                let mut chain = Vec::new();
                property_chain(e, &mut chain, true)?;
                Ex::Prop(Prop::of(&chain)?)
            }
            Expr::Index(x, flags, _) if self.top => {
                Ex::Mem(scalar_key(x, *flags, self.spec?)?.0.into())
            }
            Expr::And(v, _) | Expr::Or(v, _) => {
                let xs = v.iter().map(|x| self.expr(x)).collect::<Option<Vec<_>>>()?;
                if matches!(e, Expr::And(..)) {
                    Ex::And(xs)
                } else {
                    Ex::Or(xs)
                }
            }
            // An `if` as a value.
            Expr::Stmt(b) => match b.statements() {
                [Stmt::If(x, _)] => {
                    let c = self.expr(&x.expr)?;
                    let body = self.block(x.body.statements())?;
                    let branch = self.block(x.branch.statements())?;
                    Ex::If(Box::new(c), body, branch)
                }
                _ => return None,
            },
            Expr::FnCall(call, _) => self.call(call)?,
            _ => return None,
        })
    }

    fn call(&mut self, call: &rhai::FnCallExpr) -> Option<Ex> {
        if call.capture_parent_scope {
            return None;
        }
        let name = call.name.as_str();
        let unary = call.namespace.is_empty()
            && call.args.len() == 1
            && matches!(name, "!" | "-")
            && call.op_token.is_some();
        if call.op_token.is_none() && !unary {
            return self.function(call);
        }
        if !call.namespace.is_empty() {
            return None;
        }
        match call.args.as_slice() {
            [a] => {
                let x = Box::new(self.expr(a)?);
                match name {
                    "!" => Some(Ex::Not(x)),
                    "-" => Some(Ex::Neg(x)),
                    _ => None,
                }
            }
            [a, b] => {
                let cmp = match name {
                    "==" => Cmp::Eq,
                    "!=" => Cmp::Ne,
                    "<" => Cmp::Lt,
                    "<=" => Cmp::Le,
                    ">" => Cmp::Gt,
                    ">=" => Cmp::Ge,
                    "+" | "-" | "*" | "/" => {
                        let op = match name {
                            "+" => Arith::Add,
                            "-" => Arith::Sub,
                            "*" => Arith::Mul,
                            _ => Arith::Div,
                        };
                        let xy = Box::new([self.expr(a)?, self.expr(b)?]);
                        return Some(Ex::Arith(op, xy));
                    }
                    _ => return None,
                };
                // `type_of(x) == "name"`: a type name compared, not a string.
                if let (Expr::FnCall(t, _), Expr::StringConstant(lit, _), Cmp::Eq | Cmp::Ne) =
                    (a, b, cmp)
                {
                    if t.name == "type_of" && t.namespace.is_empty() && t.args.len() == 1 {
                        if defines(self.ast, self.modules, "type_of", 1) {
                            return None;
                        }
                        let x = Box::new(self.expr(&t.args[0])?);
                        let name = type_names().iter().find(|n| **n == lit.as_str());
                        // A name no value here has: never equal.
                        return Some(match name {
                            Some(n) => Ex::TypeIs(x, n, cmp == Cmp::Eq),
                            None => Ex::TypeIs(x, "", cmp == Cmp::Eq),
                        });
                    }
                }
                let xy = Box::new([self.expr(a)?, self.expr(b)?]);
                Some(Ex::Cmp(cmp, xy))
            }
            _ => None,
        }
    }

    /// A call of the script's own function (not from within a module) or of `alias::name`.
    fn function(&mut self, call: &rhai::FnCallExpr) -> Option<Ex> {
        let n = call.args.len();
        if self.depth >= MAX_DEPTH || n > MAX_SLOTS {
            return None;
        }
        let (callee, module) = callee(self.ast, self.modules, self.module, call)?;
        let args = call
            .args
            .iter()
            .map(|a| self.expr(a))
            .collect::<Option<Vec<_>>>()?;
        let mut inner = Cx {
            ast: self.ast,
            modules: self.modules,
            spec: self.spec,
            top: false,
            module,
            depth: self.depth + 1,
            names: Vec::new(),
            slots: 0,
        };
        for p in &callee.params {
            inner.slot(p)?;
        }
        let body = inner.block(&body_of(&callee))?;
        Some(Ex::Call(args, Arc::new(body)))
    }
}

/// The names `type_of` gives `()`, bools, integers and floats, as this build's Rhai names them.
fn type_names() -> &'static [&'static str; 4] {
    static NAMES: std::sync::OnceLock<[&'static str; 4]> = std::sync::OnceLock::new();
    NAMES.get_or_init(|| {
        let e = rhai::Engine::new_raw();
        [
            Dynamic::UNIT,
            Dynamic::from_bool(true),
            Dynamic::from_int(0 as INT),
            Dynamic::from_float(0.0 as FLOAT),
        ]
        .map(|d| -> &'static str { e.map_type_name(d.type_name()).to_string().leak() })
    })
}

/// One evaluation: the agent's view and the writes held so far (keys borrowed from the
/// compiled function, `'a`).
struct Run<'a, 'b> {
    v: &'b AgentView,
    writes: &'b mut Vec<(&'a str, MemValue)>,
}

impl<'a, 'b> Run<'a, 'b> {
    fn block(&mut self, b: &'a Block, env: &mut [Dv]) -> Result<Flow, HandBack> {
        let mut last = None;
        for s in &b.0 {
            last = match s {
                St::Let(k, e) | St::Set(k, e) => {
                    env[*k as usize] = self.value(e, env)?;
                    None
                }
                St::Write(key, t, e) => {
                    let m = match (self.value(e, env)?, t) {
                        (Some(Val::Bool(b)), MemType::Bool) => MemValue::Bool(b),
                        (Some(Val::Int(i)), MemType::Int) => MemValue::Int(i),
                        (Some(Val::Float(f)), MemType::Float) => MemValue::Float(f),
                        _ => return Err(HandBack),
                    };
                    self.writes.push((key, m));
                    None
                }
                St::If(c, yes, no) => match self.branch(c, yes, no, env)? {
                    Flow::Return(r) => return Ok(Flow::Return(r)),
                    Flow::Value(x) => x,
                },
                St::Return(e) => return Ok(Flow::Return(self.value(e, env)?)),
                St::Expr(e) => self.value(e, env)?,
            };
        }
        Ok(Flow::Value(last))
    }

    fn branch(
        &mut self,
        c: &'a Ex,
        yes: &'a Block,
        no: &'a Block,
        env: &mut [Dv],
    ) -> Result<Flow, HandBack> {
        match self.value(c, env)? {
            Some(Val::Bool(true)) => self.block(yes, env),
            Some(Val::Bool(false)) => self.block(no, env),
            _ => Err(HandBack),
        }
    }

    /// The blackboard value of `key`, the last write first.
    fn mem(&self, key: &str) -> Option<&MemValue> {
        match self.writes.iter().rev().find(|(k, _)| *k == key) {
            Some((_, m)) => Some(m),
            None => self
                .v
                .memory
                .iter()
                .find(|(k, _)| &**k == key)
                .map(|(_, m)| m),
        }
    }

    fn value(&mut self, e: &'a Ex, env: &mut [Dv]) -> Result<Dv, HandBack> {
        let bool_of = |x: Dv| match x {
            Some(Val::Bool(b)) => Ok(b),
            _ => Err(HandBack),
        };
        Ok(match e {
            Ex::Lit(x) => *x,
            Ex::Prop(p) => Some(p.read(self.v)),
            Ex::Has(key) => Some(Val::Bool(self.mem(key).is_some())),
            Ex::Mem(key) => match self.mem(key) {
                None => None,
                Some(MemValue::Bool(b)) => Some(Val::Bool(*b)),
                Some(MemValue::Int(i)) => Some(Val::Int(*i)),
                Some(MemValue::Float(f)) => Some(Val::Float(*f)),
                Some(_) => return Err(HandBack),
            },
            Ex::Var(k) => env[*k as usize],
            Ex::TypeIs(x, name, eq) => {
                let [unit, boolean, int, float] = *type_names();
                let t = match self.value(x, env)? {
                    None => unit,
                    Some(Val::Bool(_)) => boolean,
                    Some(Val::Int(_)) => int,
                    Some(Val::Float(_)) => float,
                };
                Some(Val::Bool((t == *name) == *eq))
            }
            Ex::Not(x) => Some(Val::Bool(!bool_of(self.value(x, env)?)?)),
            Ex::Neg(x) => match self.value(x, env)? {
                Some(Val::Int(i)) => Some(Val::Int(i.checked_neg().ok_or(HandBack)?)),
                Some(Val::Float(f)) => Some(Val::Float(-f)),
                _ => return Err(HandBack),
            },
            Ex::And(xs) => {
                for x in xs {
                    if !bool_of(self.value(x, env)?)? {
                        return Ok(Some(Val::Bool(false)));
                    }
                }
                Some(Val::Bool(true))
            }
            Ex::Or(xs) => {
                for x in xs {
                    if bool_of(self.value(x, env)?)? {
                        return Ok(Some(Val::Bool(true)));
                    }
                }
                Some(Val::Bool(false))
            }
            Ex::Cmp(c, xy) => {
                let (a, b) = (self.value(&xy[0], env)?, self.value(&xy[1], env)?);
                let num = |x: Dv| matches!(x, Some(Val::Int(_) | Val::Float(_)));
                let bools = matches!((a, b), (Some(Val::Bool(_)), Some(Val::Bool(_))))
                    && matches!(c, Cmp::Eq | Cmp::Ne);
                match (a, b) {
                    (Some(x), Some(y)) if bools || num(a) && num(b) => {
                        Some(Val::Bool(compare(*c, x, y)))
                    }
                    _ => return Err(HandBack),
                }
            }
            Ex::Arith(op, xy) => match (self.value(&xy[0], env)?, self.value(&xy[1], env)?) {
                (
                    Some(x @ (Val::Int(_) | Val::Float(_))),
                    Some(y @ (Val::Int(_) | Val::Float(_))),
                ) => Some(arith(*op, x, y)?),
                _ => return Err(HandBack),
            },
            Ex::If(c, yes, no) => match self.branch(c, yes, no, env)? {
                Flow::Value(x) => x,
                // A `return` inside an `if` used as a value: the interpreter's.
                Flow::Return(_) => return Err(HandBack),
            },
            Ex::Call(args, body) => {
                let mut inner = [None; MAX_SLOTS];
                for (x, a) in inner.iter_mut().zip(args) {
                    *x = self.value(a, env)?;
                }
                match self.block(body, &mut inner)? {
                    Flow::Value(x) | Flow::Return(x) => x,
                }
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::native::tests::Draw;
    use crate::script::{SandboxLimits, Script};
    use rhai::Scope;

    /// Statement functions (the sardine's `on_tick` first), with the module `m` below.
    const SCRIPT: &str = r#"
import "m" as m;
fn on_tick() {
    let prev = if this.has("f") { this["f"] } else { () };
    let elapsed = if this.has("g") { this.time - this["g"] } else { 0.0 };
    this["f"] = m::running_mean(prev, this.speed, elapsed, 2.0);
    this["g"] = this.time;
}
fn t_count() { this["i"] = this["i"] + this.kin.count; }
fn t_flags() {
    let x = this.hunger > 0.5;
    if x { this["b"] = !x; } else { this["b"] = x || this.fear > 0.2; }
}
fn t_shadow() {
    let a = 1;
    let a = a * 2 + this.kin.seen;
    if a > 3 { let a = 0.5; this["f"] = a; } else { this["i"] = a; }
    this["g"] = a * 1.0;
}
fn t_return() {
    if this.fear > 0.5 { return; }
    this["f"] = helper(this.fear, 3);
}
fn helper(x, n) { let y = x * n; if y > 1.0 { return 1.0; } y }
fn t_types() {
    this["b"] = type_of(this["i"]) == "i64" && type_of(()) == "()" && type_of(this.hunger) != "f32";
}
fn t_wrong() { this["i"] = this.hunger; }
fn t_value() {
    let v = if this.kin.count > 3 { this.kin.count } else { this.hunger };
    this["f"] = v * 1.0;
}
fn t_param() { this["f"] = m::weight(this.hunger); this["g"] = this["f"] - 1.0; }
fn t_unit() { let u = (); this["b"] = u == (); }
fn t_read_own_write() { this["i"] = 2; this["i"] = this["i"] * this.kin.seen; this["b"] = this.has("i"); }
"#;

    const MODULE: &str = r#"
fn running_mean(prev, x, elapsed, window) {
    if type_of(prev) == "()" {
        return x;
    }
    let a = elapsed / window;
    if a > 1.0 {
        a = 1.0;
    }
    prev + a * (x - prev)
}
fn weight(h) {
    if h < 0.0 { h = 0.0; }
    if h > 1.0 { h = 1.0; }
    1.0 + h
}
"#;

    fn spec() -> Arc<MemorySpec> {
        super::super::native::tests::spec_of(&[
            ("b", MemType::Bool),
            ("f", MemType::Float),
            ("g", MemType::Float),
            ("i", MemType::Int),
            ("v", MemType::Vec3),
        ])
    }

    fn names(text: &str) -> Vec<String> {
        text.split("\nfn ")
            .skip(1)
            .map(|l| l[..l.find('(').unwrap()].to_string())
            .filter(|n| n != "helper")
            .collect()
    }

    fn view(d: &mut Draw) -> AgentView {
        let mut v = AgentView {
            time: d.float(),
            speed: d.float(),
            hunger: d.float(),
            fear: d.float(),
            ..Default::default()
        };
        for c in v.cats.iter_mut() {
            c.count = d.int().rem_euclid(9);
            c.seen = d.int();
        }
        // Each key set or not, in key order; now and then a value of another type.
        let mut m: Vec<(Arc<str>, MemValue)> = Vec::new();
        if !d.next().is_multiple_of(3) {
            m.push(("b".into(), MemValue::Bool(d.next().is_multiple_of(2))));
        }
        if !d.next().is_multiple_of(3) {
            let f = if d.next().is_multiple_of(25) {
                MemValue::Int(3)
            } else {
                MemValue::Float(d.float())
            };
            m.push(("f".into(), f));
        }
        if !d.next().is_multiple_of(3) {
            m.push(("g".into(), MemValue::Float(d.float())));
        }
        if !d.next().is_multiple_of(3) {
            m.push(("i".into(), MemValue::Int(d.int())));
        }
        v.memory = m.into_iter().collect();
        v
    }

    /// A blackboard's keys and values, floats by their bits.
    fn board(v: &AgentView) -> Vec<(String, String)> {
        v.memory
            .iter()
            .map(|(k, m)| {
                let m = match m {
                    MemValue::Float(f) => format!("F{:08x}", f.to_bits()),
                    other => format!("{other:?}"),
                };
                (k.to_string(), m)
            })
            .collect()
    }

    #[test]
    fn statement_functions_write_the_interpreters_blackboard_bit_for_bit() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("m.rhai"), MODULE).unwrap();
        let file = dir.path().join("s.rhai");
        std::fs::write(&file, SCRIPT).unwrap();
        let mut s = Script::compile(&file, SCRIPT, dir.path(), &SandboxLimits::default())
            .unwrap_or_else(|d| panic!("{d}"));
        let spec = spec();
        s.declare_memory(spec.clone());
        assert!(
            s.native_on_tick().is_some(),
            "the sardine's on_tick is native"
        );
        let fns: Vec<(String, Steps)> = names(SCRIPT)
            .into_iter()
            .map(|f| {
                let steps = Steps::compile(s.ast(), s.modules(), &spec, &f)
                    .unwrap_or_else(|| panic!("`{f}` should compile"));
                (f, steps)
            })
            .collect();
        let mut d = Draw(3);
        let mut scope = Scope::new();
        let (mut compared, mut handed_back) = (0, 0);
        for _ in 0..2000 {
            let v = view(&mut d);
            for (f, steps) in &fns {
                let mut native = v.clone();
                let r = steps.run(&mut native);
                let mut this = Dynamic::from(v.clone());
                let i = s.call::<Dynamic>(&mut scope, &mut this, f);
                let interpreted = board(&this.read_lock::<AgentView>().unwrap());
                match (r, i) {
                    (Ok(()), Ok(_)) => {
                        assert_eq!(board(&native), interpreted, "`{f}`: {v:?}");
                        compared += 1;
                    }
                    (Ok(()), Err(e)) => panic!("`{f}`: native ran, interpreter: {e:?}, {v:?}"),
                    // Handed back: nothing written; the interpreter answers.
                    (Err(HandBack), _) => {
                        assert_eq!(board(&native), board(&v), "`{f}` wrote before handing back");
                        handed_back += 1;
                    }
                }
            }
        }
        assert!(
            compared > 16_000 && (500..6_000).contains(&handed_back),
            "{compared} {handed_back}"
        );
    }

    #[test]
    fn the_rest_stays_with_the_interpreter() {
        let dir = tempfile::tempdir().unwrap();
        let text = r#"
fn loop_() { while true { } }
fn vec_write() { this["v"] = this.pos; }
fn undeclared() { this["nope"] = 1; }
fn op_assign() { let a = 1; a += 2; this["i"] = a; }
fn forget() { this.forget("i"); }
fn this_in_callee() { this["f"] = uses_this(1.0); }
fn uses_this(x) { this.hunger * x }
fn string() { let s = "a"; this["b"] = s == "a"; }
fn for_loop() { for x in 0..3 { this["i"] = x; } }
"#;
        let file = dir.path().join("r.rhai");
        std::fs::write(&file, text).unwrap();
        let mut s = Script::compile(&file, text, dir.path(), &SandboxLimits::default()).unwrap();
        let spec = spec();
        s.declare_memory(spec.clone());
        for f in names(text) {
            if f == "uses_this" {
                continue;
            }
            assert!(
                Steps::compile(s.ast(), s.modules(), &spec, &f).is_none(),
                "`{f}` should stay with the interpreter"
            );
        }
        let shipped = crate::species::Species::load("behaviors/sardine.ron").unwrap();
        assert!(shipped.script.unwrap().native_on_tick().is_some());
    }
}
