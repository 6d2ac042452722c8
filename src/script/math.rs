//! Rhai's elementary functions, replaced by the engine's (`crate::math`): Rhai's own call the
//! platform's math library, whose bits may differ from one machine to the next, and a script
//! that calls `sin` must rerun bit for bit anywhere, like the native core. Registered on the
//! engine itself, these come before the standard packages' functions of the same name and
//! types. The power operator on numbers is Rhai's built-in fast path, which no registration
//! reaches: [`super::exact_power`] turns the fast paths off where a script uses it.

use crate::math;
use rhai::{Engine, FLOAT, INT};

/// The names replaced: Rhai's standard library, not the engine's API (the language server
/// documents them as Rhai's).
pub const REPLACED: [&str; 18] = [
    "sin", "cos", "tan", "sinh", "cosh", "tanh", "asin", "acos", "atan", "asinh", "acosh", "atanh",
    "exp", "ln", "log", "hypot", "**", "**=",
];

/// A function of one number.
type Unary = fn(FLOAT) -> FLOAT;

/// Registers the replacements.
pub fn register(e: &mut Engine) {
    let unary: [(&str, Unary); 15] = [
        ("sin", math::sin),
        ("cos", math::cos),
        ("tan", math::tan),
        ("sinh", math::sinh),
        ("cosh", math::cosh),
        ("tanh", math::tanh),
        ("asin", math::asin),
        ("acos", math::acos),
        ("atan", math::atan),
        ("asinh", math::asinh),
        ("acosh", math::acosh),
        ("atanh", math::atanh),
        ("exp", math::exp),
        ("ln", math::ln),
        // `log(x)`: the logarithm to base 10.
        ("log", math::log10),
    ];
    for (name, f) in unary {
        e.register_fn(name, f);
    }
    // `atan(y, x)`, as Rhai's: the angle of the point (x, y), by the function the engine's
    // bearings use (a script that works one out gets the engine's bits).
    e.register_fn("atan", |y: FLOAT, x: FLOAT| crate::frame::atan2(y, x));
    e.register_fn("hypot", math::hypot);
    // `log(x, base)`, as the standard library computes it.
    e.register_fn("log", |x: FLOAT, base: FLOAT| math::ln(x) / math::ln(base));
    e.register_fn("**", math::powf);
    e.register_fn("**", |x: INT, y: FLOAT| math::powf(x as FLOAT, y));
    e.register_fn("**", |x: FLOAT, y: INT| math::powf(x, y as FLOAT));
    e.register_fn("**=", |x: &mut FLOAT, y: FLOAT| *x = math::powf(*x, y));
    e.register_fn("**=", |x: &mut FLOAT, y: INT| {
        *x = math::powf(*x, y as FLOAT)
    });
}

#[cfg(test)]
mod tests {
    use crate::math;
    use crate::script::{new_engine, SandboxLimits};
    use rhai::{Scope, FLOAT};

    /// Evaluates `expr` with `x` and `y` set, on an engine readied for it as a script's is.
    fn eval(expr: &str, x: FLOAT, y: FLOAT) -> FLOAT {
        let mut engine = new_engine(&SandboxLimits::default());
        crate::script::exact_power(&mut engine, expr);
        let mut scope = Scope::new();
        scope.push("x", x);
        scope.push("y", y);
        engine.eval_with_scope::<FLOAT>(&mut scope, expr).unwrap()
    }

    #[test]
    fn scripts_compute_elementary_functions_with_the_engines_bits() {
        type Binary = fn(FLOAT, FLOAT) -> FLOAT;
        let cases: [(&str, Binary); 12] = [
            ("sin(x)", |x, _| math::sin(x)),
            ("cos(x)", |x, _| math::cos(x)),
            ("exp(x)", |x, _| math::exp(x)),
            ("ln(y)", |_, y| math::ln(y)),
            ("atan(x, y)", |x, y| crate::frame::atan2(x, y)),
            ("tanh(x) + log(y)", |x, y| math::tanh(x) + math::log10(y)),
            ("`${x}`; y ** 1.37", |_, y| math::powf(y, 1.37)),
            ("2.0 ** 0.5 + y", |_, y| math::powf(2.0, 0.5) + y),
            ("y ** 1.37", |_, y| math::powf(y, 1.37)),
            ("y ** x", |x, y| math::powf(y, x)),
            ("let z = y; z **= 0.61; z", |_, y| math::powf(y, 0.61)),
            ("log(y, 3.0)", |_, y| math::ln(y) / math::ln(3.0)),
        ];
        for (expr, want) in cases {
            for k in 0..500 {
                let x = (k as FLOAT - 250.0) * 0.0173 + 0.0041;
                let y = 0.37 + k as FLOAT * 0.093;
                let (got, want) = (eval(expr, x, y), want(x, y));
                assert_eq!(got.to_bits(), want.to_bits(), "{expr} at x = {x}, y = {y}");
            }
        }
    }

    /// A script's own `**`, and a module's, which runs on the engine of the script that imports
    /// it: that engine computes it exactly too, though the script itself raises nothing to a
    /// power.
    #[test]
    fn a_scripts_power_and_an_imported_one_are_exact() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("m.rhai"), "fn p(a, b) { a ** b }").unwrap();
        let file = dir.path().join("s.rhai");
        let text = "import \"m\" as m;\nfn f(a, b) { m::p(a, b) }";
        let own = dir.path().join("own.rhai");
        let own_text = "fn f(a, b) { a ** b }";
        std::fs::write(&own, own_text).unwrap();
        std::fs::write(&file, text).unwrap();
        let limits = SandboxLimits::default();
        let compile = |f: &std::path::Path, t: &str| {
            crate::script::Script::compile(f, t, dir.path(), &limits).unwrap()
        };
        for script in [compile(&file, text), compile(&own, own_text)] {
            let mut this = rhai::Dynamic::UNIT;
            for k in 0..500 {
                let (x, y) = (0.37 + k as FLOAT * 0.093, 1.37 as FLOAT);
                let got: FLOAT = script
                    .call_args(&mut Scope::new(), &mut this, "f", (x, y))
                    .unwrap();
                assert_eq!(got.to_bits(), math::powf(x, y).to_bits(), "{x} ** {y}");
            }
        }
    }
}
