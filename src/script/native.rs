//! Part of stage 4 (decision): script functions simple enough to be evaluated natively.
//!
//! Most condition slots are one expression over the agent's scalars, such as
//! `this.kin.seen > 8 && this.kin.nearest_dist < 0.5 && this.hunger < 0.5`. Through the
//! interpreter such a call costs about 1.4 µs (a fresh function-resolution cache per call, a
//! getter call per property, one operator call per comparison); evaluated here it costs a few
//! nanoseconds. At load, each function without parameters whose body is one expression of the
//! forms below is compiled to an [`Native`]; every other function is called through Rhai as
//! before.
//!
//! The forms: bool, integer and float literals; `this.p` and `this.<category>.p` for the
//! scalar properties in [`Prop`]; `!`, unary `-`; `+ - * /`; `== != < <= > >=`; `&&` and `||`;
//! the blackboard's `this.has("k")` and `this["k"]` for a key the species declares as a bool,
//! int or float; and calls of functions with parameters whose body is itself one such
//! expression over its parameters, defined in the script (`helper(this.hunger)`) or in a
//! module it imports (`school::may_school(this.hunger, this.fatigue)`): the arguments are
//! evaluated first, left to right, then the body, as the interpreter calls them. Each is typed
//! at load (bool, int or float, as the getters return them and the blackboard declares), and a
//! function whose operands would not fit (`true > 1`, a property that is not a scalar) stays
//! with the interpreter, which reports the error as it always did.
//!
//! Results are the interpreter's, bit for bit: the same getters are read from the same view,
//! integer operands are converted `as f32` where Rhai converts them, float comparisons use
//! Rhai's relative-epsilon forms (its checked build compares `x < y` as
//! `(y − x) / max(|x|, |y|) > ε`), and integer arithmetic is checked: an overflow or a
//! division by zero hands the call back to the interpreter, which raises the error. So does a
//! blackboard key that is not set (the interpreter reads it as `()`). A test
//! draws thousands of views and compares every form against the interpreter's result. A build
//! whose Rhai compares floats exactly (its `unchecked` feature) evaluates nothing natively.

use super::memory::{MemType, MemorySpec};
use super::view::{nearest_strength, AgentView, CategoryView};
use crate::perception::Category;
use crate::world::MemValue;
use rhai::{ASTFlags, Dynamic, Expr, ImmutableString, Module, Shared, Stmt, AST, FLOAT, INT};

/// A value of a natively evaluated expression.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Val {
    /// A bool.
    Bool(bool),
    /// An integer (Rhai's `INT`).
    Int(INT),
    /// A float (Rhai's `FLOAT`).
    Float(FLOAT),
}

impl Val {
    /// As the interpreter would return it.
    pub fn to_dynamic(self) -> Dynamic {
        match self {
            Val::Bool(b) => Dynamic::from_bool(b),
            Val::Int(i) => Dynamic::from_int(i),
            Val::Float(f) => Dynamic::from_float(f),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Ty {
    Bool,
    Int,
    Float,
}

/// A scalar property of the agent view, read as its registered getter reads it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Prop {
    /// `this.id`
    Id,
    /// `this.tick`
    Tick,
    /// `this.time`
    Time,
    /// `this.dt`
    Dt,
    /// `this.speed`
    Speed,
    /// `this.max_speed`
    MaxSpeed,
    /// `this.state`
    State,
    /// `this.time_in_behavior`
    TimeInBehavior,
    /// `this.stack_depth`
    StackDepth,
    /// `this.age`
    Age,
    /// `this.mass`
    Mass,
    /// `this.kind`
    Kind,
    /// `this.hunger`
    Hunger,
    /// `this.libido`
    Libido,
    /// `this.fear`
    Fear,
    /// `this.fatigue`
    Fatigue,
    /// `this.in_squad`
    InSquad,
    /// `this.is_leader`
    IsLeader,
    /// `this.at_goal`
    AtGoal,
    /// `this.slot_dist`
    SlotDist,
    /// `this.<category>.count`
    Count(u8),
    /// `this.<category>.seen`
    Seen(u8),
    /// `this.<category>.exists`
    Exists(u8),
    /// `this.<category>.nearest_dist`
    NearestDist(u8),
    /// `this.<category>.nearest_bearing`
    NearestBearing(u8),
    /// `this.<category>.nearest_elevation`
    NearestElevation(u8),
    /// `this.<category>.nearest_strength`
    NearestStrength(u8),
}

impl Prop {
    /// The property a chain of names after `this` reads, when it is a scalar one.
    pub(super) fn of(chain: &[&str]) -> Option<Prop> {
        use Prop::*;
        match chain {
            [name] => Some(match *name {
                "id" => Id,
                "tick" => Tick,
                "time" => Time,
                "dt" => Dt,
                "speed" => Speed,
                "max_speed" => MaxSpeed,
                "state" => State,
                "time_in_behavior" => TimeInBehavior,
                "stack_depth" => StackDepth,
                "age" => Age,
                "mass" => Mass,
                "kind" => Kind,
                "hunger" => Hunger,
                "libido" => Libido,
                "fear" => Fear,
                "fatigue" => Fatigue,
                "in_squad" => InSquad,
                "is_leader" => IsLeader,
                "at_goal" => AtGoal,
                "slot_dist" => SlotDist,
                _ => return None,
            }),
            [cat, field] => {
                let c = *Category::ALL.iter().find(|c| c.name() == *cat)? as u8;
                Some(match *field {
                    "count" => Count(c),
                    "seen" => Seen(c),
                    "exists" => Exists(c),
                    "nearest_dist" => NearestDist(c),
                    "nearest_bearing" => NearestBearing(c),
                    "nearest_elevation" => NearestElevation(c),
                    "nearest_strength" => NearestStrength(c),
                    _ => return None,
                })
            }
            _ => None,
        }
    }

    fn ty(self) -> Ty {
        use Prop::*;
        match self {
            Id | Tick | StackDepth | Kind | Count(_) | Seen(_) => Ty::Int,
            InSquad | IsLeader | AtGoal | Exists(_) => Ty::Bool,
            Time | Dt | Speed | MaxSpeed | State | TimeInBehavior | Age | Mass | Hunger
            | Libido | Fear | Fatigue | SlotDist | NearestDist(_) | NearestBearing(_)
            | NearestElevation(_) | NearestStrength(_) => Ty::Float,
        }
    }

    #[inline]
    pub(super) fn read(self, v: &AgentView) -> Val {
        use Prop::*;
        let cat = |c: u8| -> &CategoryView { &v.cats[c as usize] };
        match self {
            Id => Val::Int(v.id),
            Tick => Val::Int(v.tick),
            Time => Val::Float(v.time),
            Dt => Val::Float(v.dt),
            Speed => Val::Float(v.speed),
            MaxSpeed => Val::Float(v.max_speed),
            State => Val::Float(v.state),
            TimeInBehavior => Val::Float(v.time_in_behavior),
            StackDepth => Val::Int(v.stack_depth),
            Age => Val::Float(v.age),
            Mass => Val::Float(v.mass),
            Kind => Val::Int(v.kind),
            Hunger => Val::Float(v.hunger),
            Libido => Val::Float(v.libido),
            Fear => Val::Float(v.fear),
            Fatigue => Val::Float(v.fatigue),
            InSquad => Val::Bool(v.squad.is_some()),
            IsLeader => Val::Bool(super::squad::is_leader(v)),
            AtGoal => Val::Bool(super::squad::at_goal(v)),
            SlotDist => Val::Float(super::squad::slot_dist(v)),
            Count(c) => Val::Int(cat(c).count),
            Seen(c) => Val::Int(cat(c).seen),
            Exists(c) => Val::Bool(cat(c).count > 0),
            NearestDist(c) => Val::Float(cat(c).nearest_dist),
            NearestBearing(c) => Val::Float(cat(c).nearest_bearing),
            NearestElevation(c) => Val::Float(cat(c).nearest_elevation),
            NearestStrength(c) => Val::Float(nearest_strength(cat(c))),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Cmp {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Arith {
    Add,
    Sub,
    Mul,
    Div,
}

/// A typed expression tree.
#[derive(Debug, Clone, PartialEq)]
enum Node {
    Lit(Val),
    Prop(Prop),
    /// `this.has("k")`.
    Has(Box<str>),
    /// `this["k"]`, of the declared type.
    Mem(Box<str>, Ty),
    /// The value of a parameter of the function being evaluated.
    Arg(u8),
    /// A call: its arguments, then the callee's body over them.
    Call(Box<(Vec<Node>, Node)>),
    Not(Box<Node>),
    Neg(Box<Node>),
    Cmp(Cmp, Box<[Node; 2]>),
    Arith(Arith, Box<[Node; 2]>),
    And(Vec<Node>),
    Or(Vec<Node>),
}

/// Parameters a called function may have (more: the call stays with the interpreter).
const MAX_PARAMS: usize = 8;

/// Calls nested within one natively evaluated function (deeper: the interpreter's).
const MAX_DEPTH: u8 = 4;

/// A script function compiled for native evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct Native {
    root: Node,
    /// Whether it reads the blackboard (the view must then hold it).
    memory: bool,
}

/// What native evaluation leaves to the interpreter: integer arithmetic that overflowed or
/// divided by zero (the interpreter raises that error), a blackboard key that is not set.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HandBack;

impl Native {
    /// Evaluates the function for the agent `v`.
    #[inline]
    pub fn eval(&self, v: &AgentView) -> Result<Val, HandBack> {
        eval(&self.root, v, &[])
    }

    /// Whether it reads the agent's blackboard.
    pub fn reads_memory(&self) -> bool {
        self.memory
    }
}

/// Modules a script imports, by alias, as its engine holds them.
pub type Modules = [(String, Shared<Module>)];

/// The functions of `ast` that can be evaluated natively, by name (none when this build's
/// Rhai compares floats exactly: see [`checked_floats`]). `modules`: what it imports;
/// `memory`: its species' blackboard declaration (without one, no function that reads the
/// blackboard is taken: the declaration decides which keys may be read and their types).
pub fn compile_all(
    ast: &AST,
    modules: &Modules,
    memory: Option<&MemorySpec>,
) -> Vec<(String, Native)> {
    if !checked_floats() {
        return Vec::new();
    }
    // A script function `has(k)` would take `this.has("k")` (script functions come first),
    // and so would a module's method `fn T.has(k)` (Rhai makes typed methods global).
    let own_has = defines(ast, modules, "has", 1);
    ast.iter_fn_def()
        .filter(|f| f.params.is_empty() && f.this_type.is_none())
        .filter_map(|f| {
            let mut cx = Cx {
                ast,
                modules,
                memory: memory.filter(|_| !own_has),
                params: None,
                module: None,
                depth: 0,
                reads_memory: false,
            };
            let (root, _) = cx.body(f)?;
            Some((
                f.name.to_string(),
                Native {
                    root,
                    memory: cx.reads_memory,
                },
            ))
        })
        .collect()
}

/// The key of `this["k"]` (the index `x`, with its `flags`) where `spec` declares it a bool,
/// an int or a float, with that type. (`BREAK` marks a chain's last index; `?[` is another
/// flag.)
pub(super) fn scalar_key<'e>(
    x: &'e rhai::BinaryExpr,
    flags: ASTFlags,
    spec: &MemorySpec,
) -> Option<(&'e str, MemType)> {
    if !matches!(flags, ASTFlags::NONE | ASTFlags::BREAK) {
        return None;
    }
    let (Expr::ThisPtr(_), Expr::StringConstant(key, _)) = (&x.lhs, &x.rhs) else {
        return None;
    };
    let t = spec.type_of(key)?;
    matches!(t, MemType::Bool | MemType::Int | MemType::Float).then_some((key.as_str(), t))
}

/// The key of `this.has("k")` (the method call `call` on `this`) where `spec` declares it.
pub(super) fn has_key<'e>(call: &'e rhai::FnCallExpr, spec: &MemorySpec) -> Option<&'e str> {
    let [Expr::StringConstant(key, _)] = call.args.as_slice() else {
        return None;
    };
    if call.name != "has" || !call.namespace.is_empty() {
        return None;
    }
    spec.type_of(key)?;
    Some(key.as_str())
}

/// Whether the script or a module it imports defines a script function `name` of `n`
/// parameters (a module's typed method too: Rhai makes those global). Such a function takes
/// a call, or a method call on `this`, of a built-in of that name.
pub(super) fn defines(ast: &AST, modules: &Modules, name: &str, n: usize) -> bool {
    ast.iter_fn_def()
        .any(|f| f.name == name && f.params.len() == n)
        || modules.iter().any(|(_, m)| {
            m.iter_script_fn_info()
                .any(|(.., f, p, _)| f == name && p == n)
        })
}

/// The script function `call` names, as the interpreter resolves it, and the module whose
/// body it is then (`within`: the caller's): one of the script's own (not from within a
/// module, whose unqualified names are its own) or a public `alias::name` of an imported
/// module; `None` for any other call and for a typed method.
pub(super) fn callee<'m>(
    ast: &AST,
    modules: &'m Modules,
    within: Option<&'m Module>,
    call: &rhai::FnCallExpr,
) -> Option<(Shared<rhai::ScriptFuncDef>, Option<&'m Module>)> {
    let (name, n) = (call.name.as_str(), call.args.len());
    let (f, module) = if call.namespace.is_empty() {
        if within.is_some() {
            return None;
        }
        let f = ast
            .iter_fn_def()
            .find(|f| f.name == name && f.params.len() == n)?;
        (f.clone(), None)
    } else {
        let path = &call.namespace.path;
        if path.len() != 1 {
            return None;
        }
        let (_, m) = modules.iter().find(|(a, _)| a == path[0].as_str())?;
        let (.., f) = m.iter_script_fn_info().find(|(_, access, f, p, _)| {
            *f == name && *p == n && *access != rhai::FnAccess::Private
        })?;
        (f.clone(), Some(&**m))
    };
    (f.this_type.is_none()).then_some((f, module.or(within)))
}

/// Where an expression is compiled: the top of a script function (`params` `None`: `this` is
/// the agent), or the body of a function it calls, with its parameters' names and types.
struct Cx<'a> {
    ast: &'a AST,
    modules: &'a Modules,
    memory: Option<&'a MemorySpec>,
    params: Option<Vec<(ImmutableString, Ty)>>,
    /// The module whose function is being compiled (its unqualified calls are not followed).
    module: Option<&'a Module>,
    depth: u8,
    reads_memory: bool,
}

impl<'a> Cx<'a> {
    /// A function body of one expression, compiled.
    fn body(&mut self, f: &rhai::Shared<rhai::ScriptFuncDef>) -> Option<(Node, Ty)> {
        match body_of(f).as_slice() {
            [Stmt::Expr(e)] => self.compile(e),
            [Stmt::Return(Some(e), flags, _)] if *flags == ASTFlags::NONE => self.compile(e),
            [Stmt::FnCall(call, _)] => self.call(call),
            _ => None,
        }
    }
}

/// The top-level statements of the function `f`. Rhai names a body's type only inside its
/// crate: a walk of an AST that holds that one function (shared, not copied) reaches them. One
/// such AST per function keeps the load linear in the script's size.
pub(super) fn body_of(f: &rhai::Shared<rhai::ScriptFuncDef>) -> Vec<Stmt> {
    let mut lib = rhai::Module::new();
    lib.set_script_fn(f.clone());
    let one = AST::new(Vec::<Stmt>::new(), lib);
    let mut out = Vec::new();
    one.walk(&mut |path| {
        if let [rhai::ASTNode::Stmt(s)] = path {
            out.push((*s).clone());
        }
        true
    });
    out
}

/// Whether this build's Rhai compares floats with its checked build's relative epsilon, the
/// rule [`compare`] follows. A program that links Rhai with `unchecked` (features are merged
/// across a build) compares them exactly; then nothing is evaluated natively.
pub(super) fn checked_floats() -> bool {
    static CHECKED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    *CHECKED.get_or_init(|| {
        // 0.49999997 is one unit below 0.5: less than it exactly, not by the epsilon rule.
        rhai::Engine::new_raw()
            .eval_expression::<bool>("0.49999997 < 0.5")
            .is_ok_and(|lt| !lt)
    })
}

impl Cx<'_> {
    fn compile(&mut self, e: &Expr) -> Option<(Node, Ty)> {
        let top = self.params.is_none();
        match e {
            Expr::BoolConstant(b, _) => Some((Node::Lit(Val::Bool(*b)), Ty::Bool)),
            Expr::IntegerConstant(i, _) => Some((Node::Lit(Val::Int(*i)), Ty::Int)),
            Expr::FloatConstant(f, _) => Some((Node::Lit(Val::Float(**f)), Ty::Float)),
            // A called function has no `this` (the interpreter raises an error there).
            Expr::Dot(x, _, _) if top => {
                if let (Expr::ThisPtr(_), Expr::MethodCall(call, _)) = (&x.lhs, &x.rhs) {
                    return self.has(call);
                }
                let mut chain = Vec::new();
                property_chain(e, &mut chain, true)?;
                let p = Prop::of(&chain)?;
                Some((Node::Prop(p), p.ty()))
            }
            Expr::Index(x, flags, _) if top => {
                let (key, t) = scalar_key(x, *flags, self.memory?)?;
                let ty = match t {
                    MemType::Bool => Ty::Bool,
                    MemType::Int => Ty::Int,
                    _ => Ty::Float,
                };
                self.reads_memory = true;
                Some((Node::Mem(key.into(), ty), ty))
            }
            Expr::Variable(x, _, _) if x.2.is_empty() => {
                let params = self.params.as_ref()?;
                let k = params.iter().position(|(n, _)| *n == x.1)?;
                Some((Node::Arg(k as u8), params[k].1))
            }
            Expr::And(v, _) | Expr::Or(v, _) => {
                let mut nodes = Vec::with_capacity(v.len());
                for x in v.iter() {
                    let (n, t) = self.compile(x)?;
                    if t != Ty::Bool {
                        return None;
                    }
                    nodes.push(n);
                }
                let node = if matches!(e, Expr::And(..)) {
                    Node::And(nodes)
                } else {
                    Node::Or(nodes)
                };
                Some((node, Ty::Bool))
            }
            Expr::FnCall(call, _) => self.call(call),
            _ => None,
        }
    }

    /// `this.has("k")` for a declared key.
    fn has(&mut self, call: &rhai::FnCallExpr) -> Option<(Node, Ty)> {
        let key = has_key(call, self.memory?)?;
        self.reads_memory = true;
        Some((Node::Has(key.into()), Ty::Bool))
    }

    fn call(&mut self, call: &rhai::FnCallExpr) -> Option<(Node, Ty)> {
        if call.capture_parent_scope {
            return None;
        }
        if call.op_token.is_none()
            && !(call.namespace.is_empty()
                && call.args.len() == 1
                && matches!(call.name.as_str(), "!" | "-"))
        {
            return self.function(call);
        }
        if !call.namespace.is_empty() {
            return None;
        }
        let name = call.name.as_str();
        match call.args.as_slice() {
            [a] => {
                let (n, t) = self.compile(a)?;
                match (name, t) {
                    ("!", Ty::Bool) => Some((Node::Not(Box::new(n)), Ty::Bool)),
                    ("-", Ty::Int | Ty::Float) => Some((Node::Neg(Box::new(n)), t)),
                    _ => None,
                }
            }
            [a, b] => {
                let ((x, tx), (y, ty)) = (self.compile(a)?, self.compile(b)?);
                let numeric = |t: Ty| t != Ty::Bool;
                let cmp = match name {
                    "==" => Some(Cmp::Eq),
                    "!=" => Some(Cmp::Ne),
                    "<" => Some(Cmp::Lt),
                    "<=" => Some(Cmp::Le),
                    ">" => Some(Cmp::Gt),
                    ">=" => Some(Cmp::Ge),
                    _ => None,
                };
                if let Some(c) = cmp {
                    let bools = tx == Ty::Bool && ty == Ty::Bool && matches!(c, Cmp::Eq | Cmp::Ne);
                    if !(bools || numeric(tx) && numeric(ty)) {
                        return None;
                    }
                    return Some((Node::Cmp(c, Box::new([x, y])), Ty::Bool));
                }
                let op = match name {
                    "+" => Arith::Add,
                    "-" => Arith::Sub,
                    "*" => Arith::Mul,
                    "/" => Arith::Div,
                    _ => return None,
                };
                if !(numeric(tx) && numeric(ty)) {
                    return None;
                }
                let t = if tx == Ty::Int && ty == Ty::Int {
                    Ty::Int
                } else {
                    Ty::Float
                };
                Some((Node::Arith(op, Box::new([x, y])), t))
            }
            _ => None,
        }
    }

    /// A call of a script function with parameters: one of the script's own (not from within
    /// a module, whose unqualified names are its own), or `alias::name` of an imported module.
    fn function(&mut self, call: &rhai::FnCallExpr) -> Option<(Node, Ty)> {
        let n = call.args.len();
        if n > MAX_PARAMS || self.depth >= MAX_DEPTH {
            return None;
        }
        let (callee, module) = callee(self.ast, self.modules, self.module, call)?;
        let mut args = Vec::with_capacity(n);
        let mut params = Vec::with_capacity(n);
        for (a, p) in call.args.iter().zip(&callee.params) {
            let (node, ty) = self.compile(a)?;
            args.push(node);
            params.push((p.clone(), ty));
        }
        let mut inner = Cx {
            ast: self.ast,
            modules: self.modules,
            memory: self.memory,
            params: Some(params),
            module,
            depth: self.depth + 1,
            reads_memory: false,
        };
        let (body, ty) = inner.body(&callee)?;
        self.reads_memory |= inner.reads_memory;
        Some((Node::Call(Box::new((args, body))), ty))
    }
}

/// `this.a.b`: the names after `this`, in order (`head`: whether `e` is the chain's start).
pub(super) fn property_chain<'a>(e: &'a Expr, out: &mut Vec<&'a str>, head: bool) -> Option<()> {
    match e {
        Expr::Dot(x, _, _) => {
            match (&x.lhs, head) {
                (Expr::ThisPtr(_), true) => {}
                (Expr::Property(p, _), false) => out.push(p.2.as_str()),
                _ => return None,
            }
            property_chain(&x.rhs, out, false)
        }
        Expr::Property(p, _) if !head => {
            out.push(p.2.as_str());
            Some(())
        }
        _ => None,
    }
}

fn eval(n: &Node, v: &AgentView, env: &[Val]) -> Result<Val, HandBack> {
    Ok(match n {
        Node::Lit(x) => *x,
        Node::Prop(p) => p.read(v),
        Node::Has(key) => Val::Bool(v.memory.iter().any(|(k, _)| **k == **key)),
        Node::Mem(key, ty) => match (v.memory.iter().find(|(k, _)| **k == **key), ty) {
            (Some((_, MemValue::Bool(b))), Ty::Bool) => Val::Bool(*b),
            (Some((_, MemValue::Int(i))), Ty::Int) => Val::Int(*i),
            (Some((_, MemValue::Float(f))), Ty::Float) => Val::Float(*f),
            // Not set: the interpreter reads `()`. Another type than the declared one (scripts
            // cannot store one, code writing the record directly can): the interpreter's too.
            _ => return Err(HandBack),
        },
        Node::Arg(k) => env[*k as usize],
        Node::Call(call) => {
            let (args, body) = &**call;
            let mut vals = [Val::Bool(false); MAX_PARAMS];
            for (x, a) in vals.iter_mut().zip(args) {
                *x = eval(a, v, env)?;
            }
            eval(body, v, &vals[..args.len()])?
        }
        Node::Not(x) => match eval(x, v, env)? {
            Val::Bool(b) => Val::Bool(!b),
            _ => unreachable!("typed at load"),
        },
        Node::Neg(x) => match eval(x, v, env)? {
            Val::Int(i) => Val::Int(i.checked_neg().ok_or(HandBack)?),
            Val::Float(f) => Val::Float(-f),
            Val::Bool(_) => unreachable!("typed at load"),
        },
        Node::And(xs) => {
            for x in xs {
                if eval(x, v, env)? == Val::Bool(false) {
                    return Ok(Val::Bool(false));
                }
            }
            Val::Bool(true)
        }
        Node::Or(xs) => {
            for x in xs {
                if eval(x, v, env)? == Val::Bool(true) {
                    return Ok(Val::Bool(true));
                }
            }
            Val::Bool(false)
        }
        Node::Cmp(c, xy) => Val::Bool(compare(*c, eval(&xy[0], v, env)?, eval(&xy[1], v, env)?)),
        Node::Arith(op, xy) => arith(*op, eval(&xy[0], v, env)?, eval(&xy[1], v, env)?)?,
    })
}

fn as_float(x: Val) -> FLOAT {
    match x {
        Val::Int(i) => i as FLOAT,
        Val::Float(f) => f,
        Val::Bool(_) => unreachable!("typed at load"),
    }
}

/// Rhai's built-in comparison: exact for integers and bools; for floats (and an integer
/// against a float) the relative-epsilon forms of its checked build.
pub(super) fn compare(c: Cmp, a: Val, b: Val) -> bool {
    match (a, b) {
        (Val::Int(x), Val::Int(y)) => match c {
            Cmp::Eq => x == y,
            Cmp::Ne => x != y,
            Cmp::Lt => x < y,
            Cmp::Le => x <= y,
            Cmp::Gt => x > y,
            Cmp::Ge => x >= y,
        },
        (Val::Bool(x), Val::Bool(y)) => match c {
            Cmp::Eq => x == y,
            _ => x != y,
        },
        _ => {
            let (x, y) = (as_float(a), as_float(b));
            let max = if x * y == 0.0 {
                1.0
            } else {
                x.abs().max(y.abs())
            };
            if max == 0.0 {
                return matches!(c, Cmp::Eq | Cmp::Le | Cmp::Ge);
            }
            match c {
                Cmp::Eq => (x - y).abs() / max <= FLOAT::EPSILON,
                Cmp::Ne => (x - y).abs() / max > FLOAT::EPSILON,
                Cmp::Gt => (x - y) / max > FLOAT::EPSILON,
                Cmp::Ge => (x - y) / max > -FLOAT::EPSILON,
                Cmp::Lt => (y - x) / max > FLOAT::EPSILON,
                Cmp::Le => (y - x) / max > -FLOAT::EPSILON,
            }
        }
    }
}

/// Rhai's built-in arithmetic: checked for integers, IEEE for floats (an integer operand
/// converted `as f32`).
pub(super) fn arith(op: Arith, a: Val, b: Val) -> Result<Val, HandBack> {
    if let (Val::Int(x), Val::Int(y)) = (a, b) {
        let r = match op {
            Arith::Add => x.checked_add(y),
            Arith::Sub => x.checked_sub(y),
            Arith::Mul => x.checked_mul(y),
            Arith::Div => x.checked_div(y),
        };
        return r.map(Val::Int).ok_or(HandBack);
    }
    let (x, y) = (as_float(a), as_float(b));
    Ok(Val::Float(match op {
        Arith::Add => x + y,
        Arith::Sub => x - y,
        Arith::Mul => x * y,
        Arith::Div => x / y,
    }))
}

/// Every property native evaluation may read, as it reads in `v` (tests: a view filled for
/// native evaluation must read as the full view does).
#[cfg(test)]
pub(crate) fn every_property(v: &AgentView) -> Vec<Val> {
    use Prop::*;
    // A property added to `Prop` must be listed here (the match has no wildcard).
    let listed = |p: Prop| match p {
        Id | Tick | Time | Dt | Speed | MaxSpeed | State | TimeInBehavior | StackDepth | Age
        | Mass | Kind | Hunger | Libido | Fear | Fatigue | InSquad | IsLeader | AtGoal
        | SlotDist | Count(_) | Seen(_) | Exists(_) | NearestDist(_) | NearestBearing(_)
        | NearestElevation(_) | NearestStrength(_) => p,
    };
    let mut all = vec![
        Id,
        Tick,
        Time,
        Dt,
        Speed,
        MaxSpeed,
        State,
        TimeInBehavior,
        StackDepth,
        Age,
        Mass,
        Kind,
        Hunger,
        Libido,
        Fear,
        Fatigue,
        InSquad,
        IsLeader,
        AtGoal,
        SlotDist,
    ];
    for c in 0..Category::COUNT as u8 {
        all.extend([
            Count(c),
            Seen(c),
            Exists(c),
            NearestDist(c),
            NearestBearing(c),
            NearestElevation(c),
            NearestStrength(c),
        ]);
    }
    all.into_iter().map(|p| listed(p).read(v)).collect()
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::script::{SandboxLimits, Script};
    use rhai::Scope;
    use std::path::Path;
    use std::sync::Arc;

    /// Every form, each in a function the compiler must take.
    const NATIVE: &str = r#"
fn and3() { this.kin.seen > 8 && this.kin.nearest_dist < 0.5 && this.hunger < 0.5 }
fn or3() { this.fear >= 0.25 || !(this.predator.exists) || this.food.count == 0 }
fn eq_ff() { this.hunger == this.libido }
fn ne_ff() { this.hunger != this.fear }
fn le_ff() { this.fatigue <= this.hunger }
fn gt_ff() { this.speed > this.max_speed }
fn ge_ff() { this.age >= this.mass }
fn lt_if() { this.kin.count < this.hunger }
fn gt_fi() { this.time > this.tick }
fn eq_if() { this.kin.seen == this.state }
fn ne_ii() { this.kin.count != this.kin.seen }
fn le_ii() { this.id <= this.tick }
fn ge_ii() { this.kind >= this.stack_depth }
fn lt_lit() { this.tick > 2.5 }
fn arith_f() { this.hunger * 2.0 - this.fear / 3.0 + this.kin.count }
fn div_f() { this.hunger / this.fear }
fn arith_i() { this.kin.count * this.kin.seen + this.id - this.tick }
fn div_i() { this.kin.count / this.kin.seen }
fn neg_f() { -this.hunger }
fn neg_i() { -this.id }
fn ret() { return this.time_in_behavior > 1.5; }
fn bools() { this.kin.exists == this.food.exists }
fn bools_ne() { this.kin.exists != this.mate.exists }
fn strength() { this.kin.nearest_strength }
fn angles() { this.kin.nearest_bearing < 0.0 && this.obstacle.nearest_elevation >= -0.1 }
fn lit() { true }
fn squad() { this.is_leader || this.at_goal || this.slot_dist < 3.0 || this.in_squad }
fn misc() { this.dt + this.time + this.state + this.stack_depth + this.kind + this.other.count }
fn nested() { (this.hunger - this.fear) * (this.libido + 1) > this.fatigue == !(this.kin.seen < 3) }
fn lines() {
    this.kin.count > 2
        || this.fear < 0.5
}
fn one_a() { this.hunger > 0.5 } fn one_b() { this.fear }
"#;

    /// Functions the interpreter keeps: not one expression, parameters, non-scalar reads, or
    /// operands whose types do not fit.
    const INTERPRETED: &str = r#"
fn vec_read() { this.pos.y < 2.0 }
fn memory() { this.has("x") }
fn param(x) { x > 1 }
fn two() { let a = 1; a > 0 }
fn float_and() { this.hunger && this.fear > 1.0 }
fn bool_order() { this.kin.exists > this.food.exists }
fn text() { this.behavior == "wander" }
fn unknown() { this.kin.centroid }
fn method() { this.kin.nearest_dist.abs() < 1.0 }
fn empty() { }
fn effect_first() { this.hunger = 0.0; this.fear > 0.5 }
fn two_lines() {
    this.fear = 1.0;
    this.fear > 0.5
}
"#;

    fn script(text: &str) -> Script {
        Script::compile(
            Path::new("t.rhai"),
            text,
            Path::new("."),
            &SandboxLimits::default(),
        )
        .unwrap()
    }

    /// The names of the functions `text` defines (several may share a line).
    fn names(text: &str) -> Vec<String> {
        text.split("fn ")
            .skip(1)
            .map(|l| l[..l.find('(').unwrap()].to_string())
            .collect()
    }

    /// A small deterministic generator of test values.
    pub(in crate::script) struct Draw(pub(in crate::script) u64);
    impl Draw {
        pub(in crate::script) fn next(&mut self) -> u64 {
            self.0 = self
                .0
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            self.0 >> 33
        }
        pub(in crate::script) fn float(&mut self) -> FLOAT {
            // 2 − 2ε against 2 sits exactly on the epsilon of Rhai's float equality; NaN
            // against 0 reaches its `max == 0` branch.
            const SPECIAL: [FLOAT; 13] = [
                0.0,
                -0.0,
                0.5,
                1.0,
                0.25,
                1e-9,
                3.0,
                1e30,
                -2.0,
                1.5,
                2.0,
                2.0 - 2.0 * FLOAT::EPSILON,
                FLOAT::NAN,
            ];
            match self.next() % 4 {
                0 => SPECIAL[(self.next() % SPECIAL.len() as u64) as usize],
                // Close pairs: the epsilon of the float comparisons decides these.
                1 => 0.5 + (self.next() % 5) as FLOAT * 1e-8,
                _ => (self.next() % 2001) as FLOAT / 500.0 - 2.0,
            }
        }
        pub(in crate::script) fn int(&mut self) -> INT {
            match self.next() % 6 {
                0 => INT::MAX - (self.next() % 2) as INT,
                1 => INT::MIN + (self.next() % 2) as INT,
                2 => 0,
                _ => (self.next() % 21) as INT - 3,
            }
        }
    }

    fn view(d: &mut Draw) -> AgentView {
        let mut v = AgentView {
            id: d.int(),
            tick: d.int(),
            time: d.float(),
            dt: d.float(),
            speed: d.float(),
            max_speed: d.float(),
            hunger: d.float(),
            libido: d.float(),
            fear: d.float(),
            fatigue: d.float(),
            state: d.float(),
            time_in_behavior: d.float(),
            stack_depth: d.int(),
            age: d.float(),
            mass: d.float(),
            kind: d.int(),
            ..Default::default()
        };
        for c in v.cats.iter_mut() {
            c.count = d.int().rem_euclid(30);
            c.seen = d.int();
            c.nearest_dist = d.float();
            c.nearest_bearing = d.float();
            c.nearest_elevation = d.float();
        }
        v
    }

    fn same(a: &Dynamic, b: &Dynamic) -> bool {
        match (a.as_bool(), b.as_bool()) {
            (Ok(x), Ok(y)) => return x == y,
            (Err(_), Err(_)) => {}
            _ => return false,
        }
        match (a.as_int(), b.as_int()) {
            (Ok(x), Ok(y)) => return x == y,
            (Err(_), Err(_)) => {}
            _ => return false,
        }
        match (a.as_float(), b.as_float()) {
            (Ok(x), Ok(y)) => x.to_bits() == y.to_bits() || x.is_nan() && y.is_nan(),
            _ => false,
        }
    }

    #[test]
    fn a_script_of_many_functions_compiles_in_time_linear_in_its_size() {
        // Each body was once found in a copy of the whole function table: 8,000 functions
        // took 13 s. (Rhai's own parser is superlinear beyond some tens of thousands.)
        let text: String = (0..6000)
            .map(|k| format!("fn f{k}() {{ this.hunger > 0.{} }}\n", k % 9 + 1))
            .collect();
        let t = std::time::Instant::now();
        let s = script(&text);
        assert!(t.elapsed().as_secs_f64() < 3.0, "{:?}", t.elapsed());
        assert!(s.native("f0").is_some() && s.native("f5999").is_some());
    }

    #[test]
    fn every_form_compiles_and_the_rest_stays_with_the_interpreter() {
        let mixed = "fn side_a() { this.hunger = 0.0; } fn side_b() { this.fear }";
        let s = script(&format!("{NATIVE}{INTERPRETED}{mixed}"));
        for f in names(NATIVE) {
            assert!(s.native(&f).is_some(), "`{f}` should be evaluated natively");
        }
        for f in names(INTERPRETED) {
            assert!(
                s.native(&f).is_none(),
                "`{f}` should stay with the interpreter"
            );
        }
        // Two functions on one line keep their own bodies.
        let one_b = s.native("one_b").unwrap().eval(&AgentView::default());
        assert_eq!(one_b, Ok(Val::Float(0.0)));
        assert!(s.native("side_a").is_none() && s.native("side_b").is_some());
    }

    /// Runs `f` natively on `v` and through the interpreter on `this` (a copy of `v`): `None`
    /// when both answered, the same bits (asserted); the interpreter's answer when the native
    /// evaluation handed the call back. Any other pair fails the test.
    fn run_both(
        s: &Script,
        f: &str,
        v: &AgentView,
        scope: &mut Scope,
        this: &mut Dynamic,
    ) -> Option<Result<Dynamic, crate::script::CallError>> {
        let native = s.native(f).unwrap().eval(v);
        let interpreted = s.call::<Dynamic>(scope, this, f);
        match (native, interpreted) {
            (Ok(n), Ok(i)) => {
                let n = n.to_dynamic();
                assert!(
                    same(&n, &i),
                    "`{f}`: native {n:?}, interpreter {i:?}, {v:?}"
                );
                None
            }
            (Err(HandBack), i) => Some(i),
            (n, i) => panic!("`{f}`: native {n:?}, interpreter {i:?}, {v:?}"),
        }
    }

    /// Whether the interpreter failed on an integer overflow (or a division by zero).
    fn overflowed(i: &Result<Dynamic, crate::script::CallError>) -> bool {
        i.as_ref().is_err_and(|e| {
            let m = &e.diagnostic.message;
            m.contains("overflow") || m.contains("zero")
        })
    }

    #[test]
    fn native_results_are_the_interpreters_bit_for_bit() {
        let s = script(NATIVE);
        let mut d = Draw(7);
        let mut scope = Scope::new();
        let (mut compared, mut overflows) = (0, 0);
        for _ in 0..3000 {
            let v = view(&mut d);
            let mut this = Dynamic::from(v.clone());
            for f in names(NATIVE) {
                match run_both(&s, &f, &v, &mut scope, &mut this) {
                    None => compared += 1,
                    // Integer overflow: the call goes back to the interpreter, which fails.
                    Some(i) => {
                        assert!(overflowed(&i), "`{f}`: handed back, {i:?}");
                        overflows += 1;
                    }
                }
            }
        }
        assert!(
            compared > 50_000 && overflows > 100,
            "{compared} {overflows}"
        );
    }

    /// Blackboard reads and calls: the script, with the module it imports as `m`.
    const CALLS: &str = r#"
import "m" as m;
fn has_f() { this.has("f") }
fn mem_f() { this.has("f") && this["f"] > 0.5 }
fn mem_i() { this["i"] * 2 + this.kin.count }
fn mem_b() { this["b"] || this.fear > 0.5 }
fn mem_cmp() { this["i"] < this["f"] }
fn own() { helper(this.hunger, this.kin.count) }
fn helper(x, n) { x * n > 1.0 }
fn nested_own() { twice(this.fear) < 3.0 }
fn twice(x) { add(x, x) }
fn add(a, b) { a + b }
fn unused_arg() { first(this.hunger, this["i"]) }
fn first(a, b) { a }
fn unused_overflow() { first(this.hunger, this.kind * 2) }
fn modcall() { m::may(this.hunger, this.fatigue) }
fn modmem() { this.has("f") && this.time > 2.0 && m::slow(this["f"], this.max_speed, 0.3) }
fn int_param() { m::scale(this.kin.seen) > 4 }
fn mod_nested() { m::via(this.hunger) }
"#;

    /// What the interpreter keeps of the same script.
    const CALLS_INTERPRETED: &[&str] = &[
        "vec_mem",
        "undeclared",
        "this_in_callee",
        "recursive",
        "mod_unqualified",
        "string_mem",
    ];
    const CALLS_REST: &str = r#"
fn vec_mem() { this["v"] != () }
fn undeclared() { this.has("nope") }
fn this_in_callee() { uses_this(1.0) }
fn uses_this(x) { this.hunger > x }
fn recursive() { rec(1) }
fn rec(n) { rec(n) }
fn mod_unqualified() { m::outer(1.0) }
fn string_mem() { this.has("s") && this["s"] == "x" }
"#;

    const MODULE: &str = r#"
import "n" as n;
fn may(h, f) { h < 0.85 && f < 0.9 }
fn slow(x, v, k) { x < k * v }
fn scale(n) { n * 3 + 1 }
fn via(x) { n::low(x, 0.5) }
fn outer(x) { inner(x) }
fn inner(x) { x > 0.0 }
"#;

    /// A blackboard declaring `keys`, none with a start value.
    pub(in crate::script) fn spec_of(keys: &[(&str, MemType)]) -> Arc<MemorySpec> {
        Arc::new(MemorySpec::declaring(keys))
    }

    fn spec() -> Arc<MemorySpec> {
        spec_of(&[
            ("b", MemType::Bool),
            ("f", MemType::Float),
            ("i", MemType::Int),
            ("s", MemType::Str),
            ("v", MemType::Vec3),
        ])
    }

    /// The script of [`CALLS`] and [`CALLS_REST`] with its module, bound to [`spec`].
    fn calls_script() -> (tempfile::TempDir, Script) {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("m.rhai"), MODULE).unwrap();
        std::fs::write(dir.path().join("n.rhai"), "fn low(x, k) { x < k }\n").unwrap();
        let file = dir.path().join("s.rhai");
        let text = format!("{CALLS}{CALLS_REST}");
        std::fs::write(&file, &text).unwrap();
        let mut s = Script::compile(&file, &text, dir.path(), &SandboxLimits::default())
            .unwrap_or_else(|d| panic!("{d}"));
        assert!(
            s.native("has_f").is_none(),
            "no declaration yet: nothing read"
        );
        s.declare_memory(spec());
        (dir, s)
    }

    #[test]
    fn blackboard_reads_and_calls_compile_and_the_rest_stays_with_the_interpreter() {
        let (_dir, s) = calls_script();
        for f in names(CALLS) {
            let params = ["helper", "twice", "add", "first"];
            assert_eq!(
                s.native(&f).is_some(),
                !params.contains(&f.as_str()),
                "`{f}`"
            );
        }
        for f in CALLS_INTERPRETED {
            assert!(
                s.native(f).is_none(),
                "`{f}` should stay with the interpreter"
            );
        }
        assert!(s.natives_read_memory());
        assert!(!s.native("modcall").unwrap().reads_memory());
        assert!(s.native("modmem").unwrap().reads_memory());
        // A script function `has(k)` would be called instead of the blackboard's.
        let dir = tempfile::tempdir().unwrap();
        let declared = |file: &str, text: &str| {
            let mut s = Script::compile(
                &dir.path().join(file),
                text,
                dir.path(),
                &SandboxLimits::default(),
            )
            .unwrap();
            s.declare_memory(spec());
            s
        };
        let own = declared(
            "o.rhai",
            "fn knows() { this.has(\"f\") }\nfn has(k) { true }\n",
        );
        assert!(own.native("knows").is_none());
        // Nor a module's typed method `has`, which Rhai makes global.
        std::fs::write(dir.path().join("t.rhai"), "fn Agent.has(k) { true }\n").unwrap();
        let typed = declared(
            "p.rhai",
            "import \"t\" as t;\nfn knows() { this.has(\"f\") }\n",
        );
        assert!(typed.native("knows").is_none());
        let mut this = Dynamic::from(AgentView::default());
        let r = typed.call::<bool>(&mut Scope::new(), &mut this, "knows");
        assert_eq!(r.ok(), Some(true), "the module's method is the one called");
    }

    #[test]
    fn blackboard_reads_and_calls_are_the_interpreters_bit_for_bit() {
        let (_dir, s) = calls_script();
        let mut d = Draw(11);
        let mut scope = Scope::new();
        let (mut compared, mut handed_back) = (0, 0);
        let fns: Vec<String> = names(CALLS)
            .into_iter()
            .filter(|f| s.native(f).is_some())
            .collect();
        for _ in 0..3000 {
            let mut v = view(&mut d);
            // Each key set or not, in key order as a blackboard keeps them.
            let mut memory: Vec<(Arc<str>, MemValue)> = Vec::new();
            // Now and then a value of another type than the declared one (code writing the
            // record directly can store one): handed back too.
            let wrong = d.next().is_multiple_of(20);
            if !d.next().is_multiple_of(3) {
                let b = if wrong {
                    MemValue::Float(d.float())
                } else {
                    MemValue::Bool(d.next().is_multiple_of(2))
                };
                memory.push(("b".into(), b));
            }
            if !d.next().is_multiple_of(3) {
                let f = if wrong {
                    MemValue::Bool(true)
                } else {
                    MemValue::Float(d.float())
                };
                memory.push(("f".into(), f));
            }
            if !d.next().is_multiple_of(3) {
                memory.push(("i".into(), MemValue::Int(d.int())));
            }
            let unset = memory.len() < 3;
            v.memory = memory.into_iter().collect();
            let mut this = Dynamic::from(v.clone());
            for f in &fns {
                match run_both(&s, f, &v, &mut scope, &mut this) {
                    None => compared += 1,
                    // Handed back: only for an unset key (the interpreter reads `()`, which
                    // fails in arithmetic and compares unequal) or an integer overflow.
                    Some(i) => {
                        assert!(
                            unset || wrong || overflowed(&i),
                            "`{f}`: handed back, {i:?}, {v:?}"
                        );
                        handed_back += 1;
                    }
                }
            }
        }
        assert!(
            compared > 25_000 && handed_back > 3000,
            "{compared} {handed_back}"
        );
    }

    #[test]
    fn the_shipped_conditions_are_evaluated_natively() {
        for (file, fns) in [
            ("reef_fish.rhai", &["crowded"][..]),
            (
                "squad_member.rhai",
                &["is_leader", "arrived", "far_from_slot", "near_slot"],
            ),
        ] {
            let path = Path::new("behaviors").join(file);
            let s = Script::load(&path, Path::new("behaviors"), &SandboxLimits::default()).unwrap();
            for f in fns {
                assert!(s.native(f).is_some(), "{file}: `{f}`");
            }
        }
        // The reef fish's only slot is native and it has no `on_tick`: its calls fill only the
        // view's scalars.
        let fish = crate::species::Species::load("behaviors/reef_fish.ron").unwrap();
        assert!(fish.scripts_native);
        let squad = crate::species::Species::load("behaviors/squad_member.ron").unwrap();
        assert!(!squad.scripts_native, "it has an on_tick");
        // The sardine's conditions read its blackboard and call its schooling module.
        let sardine = crate::species::Species::load("behaviors/sardine.ron").unwrap();
        let script = sardine.script.as_deref().unwrap();
        for f in ["sluggish", "wants_school", "knows_food"] {
            assert!(script.native(f).is_some(), "sardine.rhai: `{f}`");
        }
    }
}
