//! Attributes for the three builds of Tribo's wide contact solver in one binary.
//!
//! The solver's source (`tribo::solver::contact_set` and `contact_wide`) is compiled three
//! times on x86-64: as the four-lane solver (SSE2, the x86-64 baseline), as the eight-lane
//! one (AVX2), and as the eight-lane one again with AVX-512VL (the same 256-bit vectors,
//! with 32 registers instead of 16), and the world picks one at run time. The source marks
//! its functions with `#[super::lane_fn]` (and its test modules with
//! `#[super::lane_tests]`); each build's parent module re-exports these attributes under
//! those names: the four-lane build the `keep` ones (the item unchanged), the eight-lane
//! builds the `avx2` or `avx512` ones, so one text gives three sets of functions, the
//! others compiled for AVX2 (`#[target_feature(enable = "avx2")]`, which their closures
//! inherit) or for AVX-512VL.
//!
//! No dependency: an attribute here only puts attributes in front of the item's tokens.

use proc_macro::TokenStream;

/// `attrs` (attribute source text) in front of `item`.
fn prefixed(attrs: &str, item: TokenStream) -> TokenStream {
    match attrs.parse::<TokenStream>() {
        Ok(prefix) => prefix.into_iter().chain(item).collect(),
        // The texts below are fixed and parse; a failure would be a bug here, reported
        // where the attribute stands.
        Err(e) => format!("compile_error!(\"tribo-lanes: {e}\");")
            .parse()
            .unwrap_or_default(),
    }
}

/// The item unchanged (the four-lane build's `lane_fn`, `lane_inline` and `lane_tests`).
#[proc_macro_attribute]
pub fn keep(_args: TokenStream, item: TokenStream) -> TokenStream {
    item
}

/// The function compiled for AVX2 (the eight-lane build's `lane_fn`). Calling it from code
/// not compiled for AVX2 is `unsafe`: the caller must know the CPU has AVX2.
#[proc_macro_attribute]
pub fn avx2(_args: TokenStream, item: TokenStream) -> TokenStream {
    prefixed("#[target_feature(enable = \"avx2\")]", item)
}

/// The function always inlined (the eight-lane build's `lane_inline`: inlined into a
/// function compiled for AVX2, it is compiled so too; a function of its own would not be).
#[proc_macro_attribute]
pub fn avx2_inline(_args: TokenStream, item: TokenStream) -> TokenStream {
    prefixed("#[inline(always)]", item)
}

/// The function compiled for AVX2 and AVX-512F/VL (the AVX-512 eight-lane build's
/// `lane_fn`): the same eight-lane code, which the compiler may now keep in 32 vector
/// registers instead of 16 (the solve passes' spills) and write with AVX-512VL's 256-bit
/// instructions. Calling it from code not compiled for these is `unsafe`: the caller must
/// know the CPU has them.
#[proc_macro_attribute]
pub fn avx512(_args: TokenStream, item: TokenStream) -> TokenStream {
    prefixed("#[target_feature(enable = \"avx2,avx512f,avx512vl\")]", item)
}

/// The test module only in a crate compiled for AVX-512F/VL as a whole (the AVX-512
/// build's `lane_tests`; see [`avx2_tests`]).
#[proc_macro_attribute]
pub fn avx512_tests(_args: TokenStream, item: TokenStream) -> TokenStream {
    prefixed(
        "#[cfg(all(target_feature = \"avx2\", target_feature = \"avx512f\", target_feature = \"avx512vl\"))]",
        item,
    )
}

/// The test module only in a crate compiled for AVX2 as a whole (the eight-lane build's
/// `lane_tests`): its tests call the eight-lane functions directly, which is safe only
/// there; elsewhere the world-level tests run them through the run-time choice.
#[proc_macro_attribute]
pub fn avx2_tests(_args: TokenStream, item: TokenStream) -> TokenStream {
    prefixed("#[cfg(target_feature = \"avx2\")]", item)
}
