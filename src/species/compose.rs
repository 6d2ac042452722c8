//! Composed behaviors as written: a behavior holding its own prioritized `behaviors`, or steps
//! run in order (`sequence`, `fallback`). Validation flattens the tree into one list in the
//! order it is written (a composite before its children), named by path (`eat/chase`), so the
//! runtime, the records and the tools keep one index per behavior; and checks what only the
//! tree can tell (a composite steers through its children, steps take no `when`, outcome
//! targets are siblings). Part of validation; reads only the species file.

use super::validate::Builder;
use super::*;
use crate::load::did_you_mean;

/// Deepest nesting of composed behaviors (the species' own list is level 0).
pub const MAX_NESTING: usize = 8;

/// One behavior of the tree, in the flattened order.
pub(super) struct Node<'a> {
    /// As written.
    pub def: &'a BehaviorDef,
    /// Path from the species' list: `eat/chase`.
    pub path: String,
    /// Index of the composite holding it.
    pub parent: Option<usize>,
    /// Nesting level (0: the species' list).
    pub level: u8,
    /// What it is made of.
    pub compose: Compose,
    /// Its children, in the order written.
    pub children: Vec<usize>,
}

impl Node<'_> {
    /// The sub-behaviors or steps it holds.
    fn parts(def: &BehaviorDef) -> (Compose, &[BehaviorDef]) {
        if !def.behaviors.is_empty() {
            (Compose::Select, &def.behaviors)
        } else if !def.sequence.is_empty() {
            (Compose::Sequence, &def.sequence)
        } else if !def.fallback.is_empty() {
            (Compose::Fallback, &def.fallback)
        } else {
            (Compose::Leaf, &[])
        }
    }
}

/// The tree of `defs` flattened: every behavior after the composite that holds it, children in
/// the order written.
pub(super) fn flatten(defs: &[BehaviorDef]) -> Vec<Node<'_>> {
    fn walk<'a>(
        defs: &'a [BehaviorDef],
        parent: Option<usize>,
        level: u8,
        prefix: &str,
        out: &mut Vec<Node<'a>>,
    ) -> Vec<usize> {
        let mut ids = Vec::new();
        for d in defs {
            let id = out.len();
            ids.push(id);
            let (compose, parts) = Node::parts(d);
            out.push(Node {
                def: d,
                path: format!("{prefix}{}", d.name),
                parent,
                level,
                compose,
                children: Vec::new(),
            });
            if (level as usize) < MAX_NESTING {
                let prefix = format!("{prefix}{}/", d.name);
                let children = walk(parts, Some(id), level + 1, &prefix, out);
                out[id].children = children;
            }
        }
        ids
    }
    let mut out = Vec::new();
    walk(defs, None, 0, "", &mut out);
    out
}

impl Builder<'_> {
    /// The checks only the tree can make, and the links the runtime reads (parents, children,
    /// outcome targets). `at` is where each behavior's name is written.
    pub(super) fn compose(&mut self, nodes: &[Node], at: &[usize], behaviors: &mut [Behavior]) {
        for (i, n) in nodes.iter().enumerate() {
            let b = n.def;
            self.cursor = at[i];
            let needle = format!("\"{}\"", b.name);
            let name = &n.path;
            if b.name.contains('/') {
                self.error_at(
                    &needle,
                    format!(
                        "behavior \"{}\": a name may not hold `/`, which separates the names of \
                         composed behaviors (`eat/chase`)",
                        b.name
                    ),
                );
            }
            let kinds = [
                !b.behaviors.is_empty(),
                !b.sequence.is_empty(),
                !b.fallback.is_empty(),
            ];
            if kinds.iter().filter(|k| **k).count() > 1 {
                self.error_at(
                    &needle,
                    format!(
                        "behavior \"{name}\" holds more than one of `behaviors`, `sequence` and \
                         `fallback`: a behavior is made of one of them (nest another behavior \
                         for the second)"
                    ),
                );
            }
            if n.level as usize >= MAX_NESTING && n.compose != Compose::Leaf {
                self.error_at(
                    &needle,
                    format!(
                        "behavior \"{name}\": composed behaviors nest at most {MAX_NESTING} deep"
                    ),
                );
            }
            if n.compose == Compose::Leaf {
                if b.steer.is_none() {
                    self.error_at(
                        &needle,
                        format!(
                            "behavior \"{name}\" has no `steer`: give it a steering recipe, or \
                             `behaviors`, a `sequence` or a `fallback` whose parts steer"
                        ),
                    );
                }
            } else {
                let what = [
                    ("steer", b.steer.is_some()),
                    ("contact", b.contact.is_some()),
                    ("on_enter", !b.on_enter.is_empty()),
                    ("response", b.response.is_some()),
                    ("focus", b.focus.is_some()),
                ];
                for (key, set) in what {
                    if set {
                        self.error_at(
                            key,
                            format!(
                                "behavior \"{name}\" is made of parts, which steer and act: \
                                 move its `{key}` into them"
                            ),
                        );
                    }
                }
            }
            let parent = n.parent.map(|p| nodes[p].compose);
            let step = matches!(parent, Some(Compose::Sequence | Compose::Fallback));
            if step {
                if b.when != Cond::Never {
                    self.error_at(
                        "when",
                        format!(
                            "step \"{name}\" has a `when`: steps run in order, each when the one \
                             before it ends (a sequence's on success, a fallback's on failure); \
                             end a step early with `fail`"
                        ),
                    );
                }
            } else if b.priority == 0 {
                self.error_at(
                    &needle,
                    format!(
                        "behavior \"{name}\" needs a `priority`: levels start at 1 (the highest)"
                    ),
                );
            }
            let siblings: Vec<usize> = match n.parent {
                Some(p) => nodes[p].children.clone(),
                None => (0..nodes.len())
                    .filter(|&j| nodes[j].parent.is_none())
                    .collect(),
            };
            let mut target = |key: &str, t: &Option<String>| -> Option<u16> {
                let t = t.as_ref()?;
                let found = siblings
                    .iter()
                    .copied()
                    .find(|&j| nodes[j].def.name == *t && j != i);
                if found.is_none() {
                    let names: Vec<&str> = siblings
                        .iter()
                        .filter(|&&j| j != i)
                        .map(|&j| nodes[j].def.name.as_str())
                        .collect();
                    self.error_at(
                        &format!("\"{t}\""),
                        format!(
                            "behavior \"{name}\": `{key}` names \"{t}\", which is not another \
                             behavior of the same list{}: it may name {}",
                            did_you_mean(t, names.iter().copied()),
                            if names.is_empty() {
                                "none (this is the only one)".to_string()
                            } else {
                                names
                                    .iter()
                                    .map(|n| format!("\"{n}\""))
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            }
                        ),
                    );
                }
                found.map(|j| j as u16)
            };
            let on_success = target("on_success", &b.on_success);
            let on_failure = target("on_failure", &b.on_failure);
            let rb = &mut behaviors[i];
            rb.parent = n.parent.map(|p| p as u16);
            rb.level = n.level;
            rb.compose = n.compose;
            rb.children = n.children.iter().map(|&c| c as u16).collect();
            rb.on_success = on_success;
            rb.on_failure = on_failure;
        }
    }

    /// Whether the behavior at `i` can ever start: its `when` can fire, it is its list's
    /// default (the species' `initial`, a composite's first part without `when`), a step, or
    /// another's outcome target.
    pub(super) fn reachable(nodes: &[Node], i: usize, initial: &str) -> bool {
        let n = &nodes[i];
        if n.def.when != Cond::Never || n.path == initial {
            return true;
        }
        let siblings: Vec<usize> = match n.parent {
            Some(p) => {
                let default = nodes[p]
                    .children
                    .iter()
                    .copied()
                    .find(|&c| nodes[c].def.when == Cond::Never);
                if nodes[p].compose != Compose::Select || default == Some(i) {
                    return true;
                }
                nodes[p].children.clone()
            }
            None => (0..nodes.len())
                .filter(|&j| nodes[j].parent.is_none())
                .collect(),
        };
        siblings.iter().any(|&j| {
            let d = nodes[j].def;
            j != i
                && (d.on_success.as_ref() == Some(&n.def.name)
                    || d.on_failure.as_ref() == Some(&n.def.name))
        })
    }
}
