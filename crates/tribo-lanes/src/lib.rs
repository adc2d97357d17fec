//! Attributes for the two builds of Tribo's wide contact solver in one binary.
//!
//! The solver's source (`tribo::solver::contact_set` and `contact_wide`) is compiled twice,
//! once as the four-lane solver (SSE2, the x86-64 baseline) and once as the eight-lane one
//! (AVX2), and the world picks one at run time. The source marks its functions with
//! `#[super::lane_fn]` (and its test modules with `#[super::lane_tests]`); each build's
//! parent module re-exports these attributes under those names: the four-lane build the
//! `keep` ones (the item unchanged), the eight-lane build the `avx2` ones, so one text gives
//! two sets of functions, the second compiled for AVX2 (`#[target_feature(enable =
//! "avx2")]`, which their closures inherit).
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

/// The test module only in a crate compiled for AVX2 as a whole (the eight-lane build's
/// `lane_tests`): its tests call the eight-lane functions directly, which is safe only
/// there; elsewhere the world-level tests run them through the run-time choice.
#[proc_macro_attribute]
pub fn avx2_tests(_args: TokenStream, item: TokenStream) -> TokenStream {
    prefixed("#[cfg(target_feature = \"avx2\")]", item)
}
