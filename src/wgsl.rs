//! Parameter blocks shared with the GPU's shaders: a `#[repr(C)]` struct
//! of f32 fields that its owner (a medium, a motion) builds from itself,
//! and its WGSL twin generated from the same declaration: the struct and
//! a reader that takes it from the words where the host packed it
//! (`gpu_block!`). Neutral ground: the media define their blocks here
//! without knowing the GPU backend, which packs them and writes the
//! readers into its shader header.

/// A block of f32 parameters with a WGSL twin.
pub trait Block: bytemuck::Pod {
    /// Its name in Rust and WGSL.
    const NAME: &'static str;
    /// Its fields in order, one f32 each.
    const FIELDS: &'static [&'static str];

    /// Its words, as the host packs them.
    fn words(&self) -> &[f32] {
        bytemuck::cast_slice(std::slice::from_ref(self))
    }

    /// The WGSL struct and a function `reader()` that builds it from the
    /// vec4 array `source` (an expression: `P.medium`), word k at
    /// `source[k / 4]`'s component k % 4.
    fn wgsl(reader: &str, source: &str) -> String {
        Self::wgsl_reading(reader, "", |k| {
            format!("{source}[{}].{}", k / 4, ["x", "y", "z", "w"][k % 4])
        })
    }

    /// The WGSL struct and a function `reader()` that builds it from the
    /// f32 array `table` from index `base` (an expression), word k at
    /// `table[base + k]`.
    fn wgsl_in_table(reader: &str, table: &str, base: &str) -> String {
        Self::wgsl_reading(reader, &format!("    let b = {base};\n"), |k| {
            format!("{table}[b + {k}u]")
        })
    }

    /// The struct and `reader()`, its body `prelude` then the struct of
    /// the words `word(k)` reads.
    fn wgsl_reading(reader: &str, prelude: &str, word: impl Fn(usize) -> String) -> String {
        let mut s = format!("struct {} {{\n", Self::NAME);
        for f in Self::FIELDS {
            s += &format!("    {f}: f32,\n");
        }
        s += &format!(
            "}}\nfn {reader}() -> {} {{\n{prelude}    return {}(",
            Self::NAME,
            Self::NAME
        );
        let args: Vec<String> = (0..Self::FIELDS.len()).map(word).collect();
        s += &args.join(", ");
        s + ");\n}\n"
    }
}

/// Declares a block: `gpu_block! { /// doc \n Name { field, ... } }` makes
/// `pub struct Name { pub field: f32, ... }` (`#[repr(C)]`, `Pod`) and its
/// [`Block`] implementation.
macro_rules! gpu_block {
    ($(#[$m:meta])* $name:ident { $($(#[$fm:meta])* $field:ident,)* }) => {
        $(#[$m])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        pub struct $name {
            $($(#[$fm])* pub $field: f32,)*
        }

        impl $crate::wgsl::Block for $name {
            const NAME: &'static str = stringify!($name);
            const FIELDS: &'static [&'static str] = &[$(stringify!($field),)*];
        }
    };
}
pub(crate) use gpu_block;

#[cfg(test)]
mod tests {
    use super::*;

    gpu_block! {
        /// A block of the test's.
        Pair {
            first,
            second,
        }
    }

    #[test]
    fn a_block_reads_back_its_words_in_order() {
        let p = Pair {
            first: 1.5,
            second: -2.0,
        };
        assert_eq!(p.words(), &[1.5, -2.0]);
        let w = Pair::wgsl("pair", "P.x");
        assert!(
            w.contains("struct Pair {\n    first: f32,\n    second: f32,\n}"),
            "{w}"
        );
        assert!(w.contains("return Pair(P.x[0].x, P.x[0].y);"), "{w}");
    }
}
