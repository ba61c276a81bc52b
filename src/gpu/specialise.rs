//! A variant's shader without the code its switches turn off, before the
//! driver sees it.
//!
//! The header's switches (`FOOTPRINT`, `SPECTRAL`, `KERR`...) are WGSL
//! constants, and `if SWITCH && ...` leaves the code behind them in the
//! module: WGSL's `&&` short-circuits, so naga lowers it to a local
//! variable stored in an `if`, which a driver sees through only after it
//! has inlined every call (Mesa's do, and llvmpipe then spends most of a
//! variant's compile time on code that is dropped later: a disk-and-sky
//! variant with footprints took 80 s on lavapipe). Here every `if` whose
//! condition the constants decide is replaced by the branch taken, the
//! short-circuit's variable followed through, and the functions no longer
//! called are removed ([`naga::compact`]), so the driver compiles only
//! what the variant runs. The result means the same: only branches that
//! cannot run are dropped.

use naga::{BinaryOperator as Op, FastHashMap};
use naga::{
    Block, Expression, Function, Handle, Literal, LocalVariable, Module, Statement, UnaryOperator,
};

/// `module` with the branches its constants rule out removed, and the
/// functions and globals left unused.
pub(crate) fn specialise(module: &mut Module) {
    let constants = module
        .constants
        .iter()
        .filter_map(|(h, c)| match module.global_expressions[c.init] {
            Expression::Literal(Literal::Bool(b)) => Some((h, b)),
            _ => None,
        })
        .collect::<FastHashMap<_, _>>();
    for (_, f) in module.functions.iter_mut() {
        prune_function(f, &constants);
    }
    for e in module.entry_points.iter_mut() {
        prune_function(&mut e.function, &constants);
    }
    naga::compact::compact(module, naga::compact::KeepUnused::No);
}

type Constants = FastHashMap<Handle<naga::Constant>, bool>;
/// Locals whose value is known where the walk is: the short-circuit's
/// variables, stored with a known value just before they are read.
type Known = FastHashMap<Handle<LocalVariable>, bool>;

fn prune_function(f: &mut Function, constants: &Constants) {
    let body = std::mem::take(&mut f.body);
    f.body = prune(body, f, constants);
    // Names keep expressions alive through compaction, and a `let` in a
    // dropped branch may name the result of a call no longer made.
    f.named_expressions.clear();
}

/// The value of boolean expression `e` where the constants (and the
/// locals in `known`) decide it.
fn value(
    f: &Function,
    constants: &Constants,
    known: &Known,
    e: Handle<Expression>,
) -> Option<bool> {
    let of = |e| value(f, constants, known, e);
    match f.expressions[e] {
        Expression::Literal(Literal::Bool(b)) => Some(b),
        Expression::Constant(c) => constants.get(&c).copied(),
        Expression::Unary {
            op: UnaryOperator::LogicalNot,
            expr,
        } => of(expr).map(|b| !b),
        // `&&` is decided by a false side, `||` by a true one.
        Expression::Binary {
            op: op @ (Op::LogicalAnd | Op::LogicalOr),
            left,
            right,
        } => {
            let decides = op == Op::LogicalOr;
            match (of(left), of(right)) {
                (Some(a), _) | (_, Some(a)) if a == decides => Some(decides),
                (Some(_), Some(_)) => Some(!decides),
                _ => None,
            }
        }
        Expression::Load { pointer } => match f.expressions[pointer] {
            Expression::LocalVariable(v) => known.get(&v).copied(),
            _ => None,
        },
        _ => None,
    }
}

/// Whether a statement ends its block (what follows it cannot run).
fn ends_block(s: &Statement) -> bool {
    matches!(
        s,
        Statement::Return { .. } | Statement::Break | Statement::Continue | Statement::Kill
    )
}

/// `block` with each `if` the constants decide replaced by its branch
/// taken, nested blocks alike.
fn prune(block: Block, f: &Function, constants: &Constants) -> Block {
    let mut out = Block::with_capacity(block.len());
    let mut known = Known::default();
    prune_into(block, f, constants, &mut known, &mut out);
    out
}

/// Appends `block`, pruned, to `out`; false where it ended `out` (a
/// `return`, `break`, `continue` or `kill` was appended).
fn prune_into(
    block: Block,
    f: &Function,
    constants: &Constants,
    known: &mut Known,
    out: &mut Block,
) -> bool {
    for (s, span) in block.span_into_iter() {
        let s = match s {
            Statement::If {
                condition,
                accept,
                reject,
            } => match value(f, constants, known, condition) {
                Some(taken) => {
                    let branch = if taken { accept } else { reject };
                    if !prune_into(branch, f, constants, known, out) {
                        return false;
                    }
                    continue;
                }
                None => {
                    known.clear();
                    Statement::If {
                        condition,
                        accept: prune(accept, f, constants),
                        reject: prune(reject, f, constants),
                    }
                }
            },
            Statement::Store { pointer, value: v } => {
                if let Expression::LocalVariable(local) = f.expressions[pointer] {
                    match value(f, constants, known, v) {
                        Some(b) => known.insert(local, b),
                        None => known.remove(&local),
                    };
                }
                Statement::Store { pointer, value: v }
            }
            Statement::Block(b) => {
                known.clear();
                Statement::Block(prune(b, f, constants))
            }
            Statement::Loop {
                body,
                continuing,
                break_if,
            } => {
                known.clear();
                Statement::Loop {
                    body: prune(body, f, constants),
                    continuing: prune(continuing, f, constants),
                    break_if,
                }
            }
            Statement::Switch { selector, cases } => {
                known.clear();
                let cases = cases
                    .into_iter()
                    .map(|c| naga::SwitchCase {
                        body: prune(c.body, f, constants),
                        ..c
                    })
                    .collect();
                Statement::Switch { selector, cases }
            }
            other => {
                // A call may write a local through a pointer it is given.
                if matches!(other, Statement::Call { .. }) {
                    known.clear();
                }
                other
            }
        };
        let ends = ends_block(&s);
        out.push(s, span);
        if ends {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn specialised(source: &str) -> Module {
        let mut m = naga::front::wgsl::parse_str(source).unwrap();
        specialise(&mut m);
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&m)
        .unwrap();
        m
    }

    fn names(m: &Module) -> Vec<&str> {
        let mut v: Vec<_> = m
            .functions
            .iter()
            .filter_map(|(_, f)| f.name.as_deref())
            .collect();
        v.sort();
        v
    }

    const SOURCE: &str = "
        const ON: bool = true;
        const OFF: bool = false;
        @group(0) @binding(0) var<storage, read_write> out: array<u32>;
        fn heavy() -> u32 { return 1u; }
        fn light() -> u32 { return 2u; }
        fn both() -> u32 { return 3u; }
        fn kept() -> u32 { return 4u; }
        @compute @workgroup_size(1)
        fn main() {
            var x = out[0];
            if OFF && x > 2u { x += heavy(); }
            if !OFF || x > 3u { x += light(); }
            if ON && x > 5u { x += kept(); }
            if OFF { x += heavy(); } else { x += both(); }
            out[0] = x;
        }";

    #[test]
    fn branches_the_constants_rule_out_go_with_their_functions() {
        // heavy() is called only behind OFF; kept() behind ON and a
        // runtime test stays.
        assert_eq!(names(&specialised(SOURCE)), ["both", "kept", "light"]);
    }

    #[test]
    fn a_return_in_a_branch_taken_ends_the_block() {
        let m = specialised(
            "
            const ON: bool = true;
            fn f(a: u32) -> u32 {
                if ON { return a; }
                return a + 1u;
            }
            @compute @workgroup_size(1)
            fn main() { _ = f(1u); }",
        );
        let f = m.functions.iter().next().unwrap().1;
        assert_eq!(
            f.body
                .iter()
                .filter(|s| matches!(s, Statement::Return { .. }))
                .count(),
            1
        );
    }
}
