//! Rust source for one robot: a generic struct, its `Dynamics` implementation and link
//! kinematics, as straight-line, allocation-free, panic-free code over `eomgen_runtime::Real`.

use std::collections::{BTreeMap, BTreeSet};

use proc_macro2::{Ident, Literal, TokenStream};
use quote::{format_ident, quote};

use super::names::{comment_text, snake, upper_camel, Scope};
use crate::cas::{Expr, Id, OpCount, Order, Program, Symbol, SymbolKind};
use crate::dynamics::{Derivation, Route};
use crate::model::Model;

/// What the emitted file is called and says about itself.
#[derive(Clone, Debug)]
pub struct EmitOptions {
    /// The generated type, e.g. `Panda`; the link enum is `PandaLink`.
    pub type_name: String,
    /// The URDF's file name (no directories: output must not depend on where files live).
    pub source_name: String,
    /// How to regenerate the file, for the banner.
    pub regenerate: String,
}

/// How a function's outputs are laid out.
enum Shape {
    Scalar,
    Vector,
    /// Rows x columns, row-major.
    Matrix(usize, usize),
}

/// Turns program expressions into tokens.
struct Ctx<'a> {
    symbols: &'a [Symbol],
    /// Parameter symbol index -> struct field.
    fields: &'a BTreeMap<u32, Ident>,
}

/// Tokens of an expression and whether it is a sum (needs parentheses inside a product).
struct Tok {
    ts: TokenStream,
    sum: bool,
    /// A plain name or literal call, cheap to repeat.
    atom: bool,
}

fn lit(v: f64) -> TokenStream {
    if v.is_nan() {
        return quote!(T::nan());
    }
    if v.is_infinite() {
        return if v > 0.0 {
            quote!(T::from_f64(f64::INFINITY))
        } else {
            quote!(T::from_f64(f64::NEG_INFINITY))
        };
    }
    if v == 0.0 {
        return quote!(T::zero());
    }
    if v == 1.0 {
        return quote!(T::one());
    }
    let l = Literal::f64_unsuffixed(v.abs());
    if v < 0.0 {
        quote!((-T::from_f64(#l)))
    } else {
        quote!(T::from_f64(#l))
    }
}

impl Ctx<'_> {
    fn input(&self, s: u32, trig: &mut BTreeSet<(usize, bool)>, sin: Option<bool>) -> TokenStream {
        let sym = &self.symbols[s as usize];
        let idx = |i: usize| Literal::usize_unsuffixed(i);
        match (sym.kind, sin) {
            (SymbolKind::Q(i), Some(is_sin)) => {
                trig.insert((i, is_sin));
                let name = if is_sin {
                    format_ident!("s{}", i)
                } else {
                    format_ident!("c{}", i)
                };
                quote!(#name)
            }
            (SymbolKind::Q(i), None) => {
                let i = idx(i);
                quote!(q[#i])
            }
            (SymbolKind::Qd(i), None) => {
                let i = idx(i);
                quote!(qd[#i])
            }
            (SymbolKind::Tau(i), None) => {
                let i = idx(i);
                quote!(tau[#i])
            }
            (SymbolKind::Qdd(i), None) => {
                let i = idx(i);
                quote!(qdd[#i])
            }
            (SymbolKind::Param, None) => {
                let f = &self.fields[&s];
                quote!(self.#f)
            }
            (_, Some(is_sin)) => {
                let inner = self.input(s, trig, None);
                if is_sin {
                    quote!(#inner.sin())
                } else {
                    quote!(#inner.cos())
                }
            }
        }
    }

    fn expr(&self, e: &Expr, trig: &mut BTreeSet<(usize, bool)>) -> Tok {
        match e {
            Expr::Const(c) => Tok {
                ts: lit(*c),
                sum: false,
                atom: true,
            },
            Expr::Input(s) => Tok {
                ts: self.input(*s, trig, None),
                sum: false,
                atom: true,
            },
            Expr::Temp(t) => {
                let name = format_ident!("t{}", t);
                Tok {
                    ts: quote!(#name),
                    sum: false,
                    atom: true,
                }
            }
            Expr::Sin(a) | Expr::Cos(a) => {
                let is_sin = matches!(e, Expr::Sin(_));
                if let Expr::Input(s) = **a {
                    return Tok {
                        ts: self.input(s, trig, Some(is_sin)),
                        sum: false,
                        atom: true,
                    };
                }
                let inner = self.paren(a, trig);
                let ts = if is_sin {
                    quote!(#inner.sin())
                } else {
                    quote!(#inner.cos())
                };
                Tok {
                    ts,
                    sum: false,
                    atom: false,
                }
            }
            Expr::Sqrt(a) => {
                let inner = self.paren(a, trig);
                Tok {
                    ts: quote!(#inner.sqrt()),
                    sum: false,
                    atom: false,
                }
            }
            Expr::Sign(a) => {
                let inner = self.paren(a, trig);
                Tok {
                    ts: quote!(#inner.signum()),
                    sum: false,
                    atom: false,
                }
            }
            Expr::Add(c, terms) => {
                // Positive terms first, so that the sum starts without a negation when it can.
                let mut parts: Vec<(bool, TokenStream)> = Vec::new();
                for (t, k) in terms {
                    let tt = self.expr(t, trig);
                    let body = if k.abs() == 1.0 {
                        tt.ts
                    } else {
                        let coef = lit(k.abs());
                        let inner = if tt.sum { paren(tt.ts) } else { tt.ts };
                        quote!(#coef * #inner)
                    };
                    parts.push((*k < 0.0, body));
                }
                if *c != 0.0 {
                    parts.push((*c < 0.0, lit(c.abs())));
                }
                parts.sort_by_key(|p| p.0);
                let mut ts = TokenStream::new();
                for (i, (neg, body)) in parts.into_iter().enumerate() {
                    ts = match (i, neg) {
                        (0, false) => body,
                        (0, true) => quote!(-#body),
                        (_, false) => quote!(#ts + #body),
                        (_, true) => quote!(#ts - #body),
                    };
                }
                Tok {
                    ts,
                    sum: true,
                    atom: false,
                }
            }
            Expr::Mul(factors) => {
                let mut num: Vec<TokenStream> = Vec::new();
                let mut den: Vec<TokenStream> = Vec::new();
                for (f, x) in factors {
                    let ft = self.expr(f, trig);
                    let raw = ft.ts.clone();
                    let base = if ft.sum { paren(ft.ts) } else { ft.ts };
                    let n = x.unsigned_abs() as usize;
                    let power = if n == 1 {
                        base
                    } else if ft.atom {
                        join_mul(std::iter::repeat_n(base, n).collect())
                    } else {
                        // Evaluate a compound base once.
                        let prod = join_mul(std::iter::repeat_n(quote!(b), n).collect());
                        quote!({ let b = #raw; #prod })
                    };
                    if *x > 0 {
                        num.push(power);
                    } else {
                        den.push(power);
                    }
                }
                let n = if num.is_empty() {
                    quote!(T::one())
                } else {
                    join_mul(num)
                };
                let ts = match den.len() {
                    0 => n,
                    1 => {
                        let d = &den[0];
                        quote!(#n / #d)
                    }
                    _ => {
                        let d = join_mul(den);
                        quote!(#n / (#d))
                    }
                };
                Tok {
                    ts,
                    sum: false,
                    atom: false,
                }
            }
        }
    }

    fn paren(&self, e: &Expr, trig: &mut BTreeSet<(usize, bool)>) -> TokenStream {
        let t = self.expr(e, trig);
        if t.atom {
            t.ts
        } else {
            paren(t.ts)
        }
    }
}

fn paren(ts: TokenStream) -> TokenStream {
    quote!((#ts))
}

fn join_mul(items: Vec<TokenStream>) -> TokenStream {
    let mut it = items.into_iter();
    let first = it.next().unwrap_or_else(|| quote!(T::one()));
    it.fold(first, |acc, x| quote!(#acc * #x))
}

/// Temporaries per chunk of `let`s (see `body`).
const LET_CHUNK: usize = 64;

/// Straight-line body computing `outputs` in the given shape, and its operation count.
fn body(d: &Derivation, cx: &Ctx<'_>, outputs: &[Id], shape: Shape) -> (TokenStream, OpCount) {
    let program = Program::ordered(&d.graph, outputs, Order::Levels);
    let mut trig = BTreeSet::new();
    // Temporaries go in chunks: `let (t0, .., t63) = { let t0 = ..; ..; (t0, .., t63) };`.
    // Every `let` opens a lexical scope nested in the previous one, and LLVM's debug-info
    // writer recurses once per level: a few thousand plain `let`s in one function overflow
    // rustc's stack in debug builds. Chunking bounds the depth at chunks + chunk size.
    let defs: Vec<(Ident, TokenStream)> = program
        .temps
        .iter()
        .enumerate()
        .map(|(k, e)| (format_ident!("t{}", k), cx.expr(e, &mut trig).ts))
        .collect();
    let temps: Vec<TokenStream> = if defs.len() <= LET_CHUNK {
        defs.iter()
            .map(|(name, v)| quote!(let #name = #v;))
            .collect()
    } else {
        defs.chunks(LET_CHUNK)
            .map(|chunk| {
                let names: Vec<&Ident> = chunk.iter().map(|(n, _)| n).collect();
                let lets = chunk.iter().map(|(name, v)| quote!(let #name = #v;));
                quote!(let (#(#names),*,) = { #(#lets)* (#(#names),*,) };)
            })
            .collect()
    };
    let outs: Vec<TokenStream> = program
        .outputs
        .iter()
        .map(|e| cx.expr(e, &mut trig).ts)
        .collect();
    let ops = program.ops();
    // One sin_cos per joint angle, computed up front.
    let joints: BTreeSet<usize> = trig.iter().map(|t| t.0).collect();
    let pre: Vec<TokenStream> = joints
        .iter()
        .map(|&i| {
            let (s, c) = (format_ident!("s{}", i), format_ident!("c{}", i));
            let (has_sin, has_cos) = (trig.contains(&(i, true)), trig.contains(&(i, false)));
            let i = Literal::usize_unsuffixed(i);
            match (has_sin, has_cos) {
                (true, true) => quote!(let (#s, #c) = q[#i].sin_cos();),
                (true, false) => quote!(let #s = q[#i].sin();),
                _ => quote!(let #c = q[#i].cos();),
            }
        })
        .collect();
    let result = match shape {
        Shape::Scalar => outs[0].clone(),
        Shape::Vector => quote!([#(#outs),*]),
        Shape::Matrix(_, cols) => {
            let rows: Vec<TokenStream> = outs
                .chunks(cols.max(1))
                .map(|r| quote!([#(#r),*]))
                .collect();
            if cols == 0 {
                let n = match shape {
                    Shape::Matrix(r, _) => r,
                    _ => 0,
                };
                let empty = std::iter::repeat_n(quote!([]), n);
                quote!([#(#empty),*])
            } else {
                quote!([#(#rows),*])
            }
        }
    };
    (quote!(#(#pre)* #(#temps)* #result), ops)
}

fn doc(lines: &[String]) -> TokenStream {
    let attrs = lines.iter().map(|l| {
        let text = format!(" {}", comment_text(l));
        quote!(#[doc = #text])
    });
    quote!(#(#attrs)*)
}

fn ops_line(ops: &OpCount) -> String {
    format!("Operations: {ops}.")
}

/// Emits the whole file (unformatted tokens; see [`super::format`]).
pub fn emit_tokens(
    model: &Model,
    d: &Derivation,
    opts: &EmitOptions,
) -> (TokenStream, Vec<(String, OpCount)>) {
    let n = d.dof;
    let ty = format_ident!("{}", opts.type_name);
    let link_ty = format_ident!("{}Link", opts.type_name);
    let mut counts = Vec::new();

    // Parameters become fields.
    let mut field_scope = Scope::with_reserved(&["_marker"]);
    let mut fields = BTreeMap::new();
    let mut field_defs = Vec::new();
    let mut field_defaults = Vec::new();
    for (name, id, value) in &d.params {
        let sym = d.graph.as_symbol(*id).expect("parameter symbol");
        let f = format_ident!("{}", field_scope.claim(snake(name, "p")));
        let docline = format!(
            " `{}` ({} {}).",
            comment_text(&name.replace('`', "'")),
            crate::report::value_source(name),
            value
        );
        field_defs.push(quote!(#[doc = #docline] pub #f: T,));
        let l = lit(*value);
        field_defaults.push(quote!(#f: #l,));
        fields.insert(sym, f);
    }
    let cx = Ctx {
        symbols: d.graph.symbols(),
        fields: &fields,
    };

    let flat = |m: &Vec<Vec<Id>>| -> Vec<Id> { m.iter().flatten().copied().collect() };
    let func = |name: &str, outputs: Vec<Id>, shape: Shape, counts: &mut Vec<(String, OpCount)>| {
        let (b, ops) = body(d, &cx, &outputs, shape);
        counts.push((name.to_string(), ops));
        (b, ops_line(&ops))
    };

    let f = &d.fast;
    let route = |r: Route, rec: &str| format!("Route: {}.", r.describe(rec));
    let (mm, mm_ops) = func(
        "mass_matrix",
        flat(&f.mass_matrix.1),
        Shape::Matrix(n, n),
        &mut counts,
    );
    let mm_route = route(f.mass_matrix.0, "composite-rigid-body algorithm");
    let (gr, gr_ops) = func("gravity", f.gravity.1.clone(), Shape::Vector, &mut counts);
    let gr_route = route(f.gravity.0, "Newton-Euler");
    let (bi, bi_ops) = func("bias", f.bias.1.clone(), Shape::Vector, &mut counts);
    let bi_route = route(f.bias.0, "Newton-Euler");
    let (cm, cm_ops) = func(
        "coriolis_matrix",
        flat(&f.coriolis_matrix.1),
        Shape::Matrix(n, n),
        &mut counts,
    );
    let (id, id_ops) = func(
        "inverse_dynamics",
        f.tau.1.clone(),
        Shape::Vector,
        &mut counts,
    );
    let id_route = route(f.tau.0, "Newton-Euler");
    let (ke, ke_ops) = func(
        "kinetic_energy",
        vec![f.kinetic_energy],
        Shape::Scalar,
        &mut counts,
    );
    let (pe, pe_ops) = func(
        "potential_energy",
        vec![d.potential_energy],
        Shape::Scalar,
        &mut counts,
    );
    let np = n * n.saturating_sub(1) / 2;
    let (cf, cf_ops) = func(
        "centrifugal",
        flat(&f.centrifugal.1),
        Shape::Matrix(n, n),
        &mut counts,
    );
    let (cp, cp_ops) = func(
        "coriolis_pairs",
        flat(&f.coriolis_pairs.1),
        Shape::Matrix(n, np),
        &mut counts,
    );
    // Forward dynamics: M and h = b + G, then the unrolled sparse L^T D L solve, all in one
    // program; the pivots come out too, to report a mass matrix that is not positive definite.
    let mut fd_outputs = f.forward_dynamics.clone();
    fd_outputs.extend(&f.pivots);
    let (fd_body, fd_ops) = func("forward_dynamics", fd_outputs, Shape::Vector, &mut counts);
    let fd_len = Literal::usize_unsuffixed(2 * n);
    let fd_x: Vec<TokenStream> = (0..n)
        .map(|i| {
            let i = Literal::usize_unsuffixed(i);
            quote!(o[#i])
        })
        .collect();
    let fd_pivots: Vec<TokenStream> = (0..n)
        .map(|i| {
            let i = Literal::usize_unsuffixed(n + i);
            quote!(o[#i])
        })
        .collect();

    // Links.
    let mut link_scope = Scope::with_reserved(&["ALL"]);
    let variants: Vec<Ident> = d
        .frames
        .iter()
        .map(|f| format_ident!("{}", link_scope.claim(upper_camel(&f.name, "Link"))))
        .collect();
    let link_names: Vec<Literal> = d.frames.iter().map(|f| Literal::string(&f.name)).collect();
    let nlinks = variants.len();
    let mut pose_arms = Vec::new();
    let mut jac_arms = Vec::new();
    for (f, v) in d.frames.iter().zip(&variants) {
        let mut outs: Vec<Id> = f.position.to_vec();
        outs.extend(f.rotation.iter().flatten());
        let (pb, _) = body(d, &cx, &outs, Shape::Vector);
        pose_arms.push(quote!(#link_ty::#v => { let o = { #pb }; ::eomgen_runtime::Pose { translation: [o[0], o[1], o[2]], rotation: [[o[3], o[4], o[5]], [o[6], o[7], o[8]], [o[9], o[10], o[11]]] } }));
        let (jb, _) = body(d, &cx, &flat(&f.jacobian), Shape::Matrix(6, n));
        jac_arms.push(quote!(#link_ty::#v => { #jb }));
    }

    let joint_names: Vec<Literal> = model
        .joints
        .iter()
        .map(|j| Literal::string(&j.name))
        .collect();
    let type_doc = doc(&[
        format!(
            "Rigid-body dynamics of `{}` ({} joints), generated by eomgen.",
            model.name.replace('`', "'"),
            n
        ),
        String::new(),
        "Generic over the scalar type (`f64` by default, `f32` for single-precision firmware)."
            .into(),
        "`Default` holds the URDF's parameter values.".into(),
    ]);
    let link_doc = doc(&[format!(
        "The URDF links of [`{}`], one variant per link.",
        opts.type_name
    )]);
    let gr_doc = doc(&[gr_route, gr_ops]);
    let bi_doc = doc(&[bi_route, bi_ops]);
    let cm_doc = doc(&[
        route(
            f.coriolis_matrix.0,
            "Echeandia and Wensing's O(N^2) recursion on composite inertias and momenta",
        ),
        cm_ops,
    ]);
    // Joint effects change the meaning of some functions: say so where they apply.
    let friction_note = |what: &str| -> Vec<String> {
        if model.include_friction {
            vec![
                String::new(),
                format!(
                    "{what} the joint friction F(qd) of [`{}::friction`].",
                    opts.type_name
                ),
            ]
        } else {
            Vec::new()
        }
    };
    let armature: Vec<String> = model
        .joints
        .iter()
        .filter(|j| j.armature != 0.0)
        .map(|j| format!("`{}` {}", j.name.replace('`', "'"), j.armature))
        .collect();
    let armature_note = |what: &str| -> Vec<String> {
        if armature.is_empty() {
            Vec::new()
        } else {
            vec![
                String::new(),
                format!("{what} rotor inertia (armature): {}.", armature.join(", ")),
            ]
        }
    };
    let with_notes = |mut lines: Vec<String>, notes: &[Vec<String>]| {
        for n in notes {
            lines.extend(n.iter().cloned());
        }
        doc(&lines)
    };
    let mm_doc = with_notes(
        vec![mm_route, mm_ops],
        &[armature_note("The diagonal includes")],
    );
    let id_doc = with_notes(
        vec![id_route, id_ops],
        &[
            friction_note("`tau = M qdd + b + G + F(qd)`: includes"),
            armature_note("M includes"),
        ],
    );
    let fd_doc = with_notes(
        vec![
            "Route: M and b + G as in `mass_matrix` and `bias`, then an unrolled L^T D L solve without fill-in.".into(),
            fd_ops,
            String::new(),
            "Returns NaN in every entry when M(q) is not positive definite (it cannot be for a valid".into(),
            "model and finite inputs); `try_forward_dynamics` says which pivot failed.".into(),
        ],
        &[
            friction_note("`qdd = M^-1 (tau - b - G - F(qd))`: includes"),
            armature_note("M includes"),
        ],
    );
    let ke_doc = with_notes(vec![ke_ops], &[armature_note("Includes the")]);
    let pe_doc = doc(&[pe_ops]);
    let cf_doc = doc(&[
        "Craig's centrifugal matrix C(q): `b = B(q) [qd qd] + C(q) [qd^2]`.".into(),
        String::new(),
        route(
            f.centrifugal.0,
            "second velocity derivatives of the Newton-Euler bias",
        ),
        cf_ops,
    ]);
    let cp_doc = doc(&[
        format!("Craig's Coriolis matrix B(q), N x N(N-1)/2 = {n} x {np}, columns for qd_j qd_k with j < k in the order (0,1), (0,2), ..., (1,2), ..."),
        String::new(),
        route(f.coriolis_pairs.0, "second velocity derivatives of the Newton-Euler bias"),
        cp_ops,
    ]);

    let friction_fn = if model.include_friction {
        let (fr, fr_ops) = func("friction", d.friction.clone(), Shape::Vector, &mut counts);
        let smoothing = if model.coulomb_smoothing > 0.0 {
            format!(
                "`s(v) = v / sqrt(v^2 + eps^2)`, the sign smoothed below `eps = {}` (rad/s or m/s)",
                model.coulomb_smoothing
            )
        } else {
            "`s(v) = sign(v)`, 0 at rest (no stiction)".to_string()
        };
        let coefficients: Vec<String> = model
            .joints
            .iter()
            .map(|j| {
                format!(
                    "`{}`: damping {}, friction {}",
                    j.name.replace('`', "'"),
                    j.damping,
                    j.friction
                )
            })
            .collect();
        let fr_doc = doc(&[
            "Joint friction effort `F(qd)`, per joint `damping qd + friction s(qd)` from the URDF's".into(),
            format!("`<dynamics damping friction>`, with {smoothing}."),
            "The effort the actuators must supply against friction (the joints feel `-F`); it is".into(),
            "part of `inverse_dynamics` and `forward_dynamics`, not of `bias`.".into(),
            String::new(),
            format!("Coefficients: {}.", coefficients.join("; ")),
            String::new(),
            fr_ops,
        ]);
        let nn = Literal::usize_unsuffixed(n);
        quote! {
            #fr_doc
            pub fn friction(&self, qd: &[T; #nn]) -> [T; #nn] { #fr }
        }
    } else {
        TokenStream::new()
    };
    let (n, np, nlinks) = (
        Literal::usize_unsuffixed(n),
        Literal::usize_unsuffixed(np),
        Literal::usize_unsuffixed(nlinks),
    );
    let tokens = quote! {
        #type_doc
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct #ty<T = f64> {
            #(#field_defs)*
            _marker: ::core::marker::PhantomData<T>,
        }

        impl<T: ::eomgen_runtime::Real> ::core::default::Default for #ty<T> {
            fn default() -> Self {
                #ty { #(#field_defaults)* _marker: ::core::marker::PhantomData }
            }
        }

        #link_doc
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum #link_ty {
            #(#variants),*
        }

        impl #link_ty {
            /// Every link, in URDF order.
            pub const ALL: [#link_ty; #nlinks] = [#(#link_ty::#variants),*];

            /// The URDF name of the link.
            pub const fn name(self) -> &'static str {
                match self {
                    #(#link_ty::#variants => #link_names),*
                }
            }
        }

        #[allow(unused_variables, clippy::approx_constant, clippy::excessive_precision, clippy::unreadable_literal, clippy::neg_multiply, clippy::double_parens, clippy::identity_op, clippy::needless_range_loop, clippy::let_and_return)]
        impl<T: ::eomgen_runtime::Real> #ty<T> {
            /// Number of joint coordinates.
            pub const DOF: usize = #n;

            #cf_doc
            pub fn centrifugal(&self, q: &[T; #n]) -> [[T; #n]; #n] { #cf }

            #cp_doc
            pub fn coriolis_pairs(&self, q: &[T; #n]) -> [[T; #np]; #n] { #cp }

            /// Forward dynamics `qdd = M(q)^-1 (tau - b(q, qd) - G(q))`, or which pivot of the
            /// `L^T D L` factorization of M(q) was not positive (a non-physical model or
            /// non-finite input); see `Dynamics::forward_dynamics` for the operation count.
            /// `Ok` holds only finite numbers: a non-finite component `i` of the solution (from
            /// a non-finite `qd` or `tau`, or a `q` that leaves M(q) finite) is reported as
            /// `FactorError::NonFinite { pivot: i }`.
            pub fn try_forward_dynamics(&self, q: &[T; #n], qd: &[T; #n], tau: &[T; #n]) -> ::core::result::Result<[T; #n], ::eomgen_runtime::FactorError> {
                let o: [T; #fd_len] = { #fd_body };
                let pivots = [#(#fd_pivots),*];
                for (pivot, d) in pivots.iter().enumerate() {
                    if !d.is_finite() {
                        return Err(::eomgen_runtime::FactorError::NonFinite { pivot });
                    }
                    if *d <= T::zero() {
                        return Err(::eomgen_runtime::FactorError::NotPositiveDefinite { pivot });
                    }
                }
                let qdd = [#(#fd_x),*];
                for (pivot, x) in qdd.iter().enumerate() {
                    if !x.is_finite() {
                        return Err(::eomgen_runtime::FactorError::NonFinite { pivot });
                    }
                }
                Ok(qdd)
            }

            #friction_fn

            /// Pose of a link frame in the world (root) frame.
            pub fn link_pose(&self, link: #link_ty, q: &[T; #n]) -> ::eomgen_runtime::Pose<T> {
                match link { #(#pose_arms)* }
            }

            /// The 6 x N Jacobian of a link frame: rows vx, vy, vz, wx, wy, wz in world axes, at the link origin.
            pub fn link_jacobian(&self, link: #link_ty, q: &[T; #n]) -> [[T; #n]; 6] {
                match link { #(#jac_arms)* }
            }
        }

        #[allow(unused_variables, clippy::approx_constant, clippy::excessive_precision, clippy::unreadable_literal, clippy::neg_multiply, clippy::double_parens, clippy::identity_op, clippy::needless_range_loop, clippy::let_and_return)]
        impl<T: ::eomgen_runtime::Real> ::eomgen_runtime::Dynamics<T, #n> for #ty<T> {
            const JOINT_NAMES: [&'static str; #n] = [#(#joint_names),*];

            #mm_doc
            fn mass_matrix(&self, q: &[T; #n]) -> [[T; #n]; #n] { #mm }

            #gr_doc
            fn gravity(&self, q: &[T; #n]) -> [T; #n] { #gr }

            #bi_doc
            fn bias(&self, q: &[T; #n], qd: &[T; #n]) -> [T; #n] { #bi }

            #cm_doc
            fn coriolis_matrix(&self, q: &[T; #n], qd: &[T; #n]) -> [[T; #n]; #n] { #cm }

            #id_doc
            fn inverse_dynamics(&self, q: &[T; #n], qd: &[T; #n], qdd: &[T; #n]) -> [T; #n] { #id }

            #fd_doc
            fn forward_dynamics(&self, q: &[T; #n], qd: &[T; #n], tau: &[T; #n]) -> [T; #n] {
                match self.try_forward_dynamics(q, qd, tau) {
                    Ok(qdd) => qdd,
                    Err(_) => [T::nan(); #n],
                }
            }

            #ke_doc
            fn kinetic_energy(&self, q: &[T; #n], qd: &[T; #n]) -> T { #ke }

            #pe_doc
            fn potential_energy(&self, q: &[T; #n]) -> T { #pe }
        }
    };
    (tokens, counts)
}
