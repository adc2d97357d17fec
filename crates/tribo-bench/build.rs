//! Records the C flags that boxdd-sys's C build saw (the same environment in the same cargo
//! invocation), so the benchmark can print how Box2D was compiled.

fn main() {
    for var in ["CFLAGS", "TARGET_CFLAGS", "CFLAGS_x86_64_unknown_linux_gnu", "CC"] {
        println!("cargo:rerun-if-env-changed={var}");
    }
    let cflags = std::env::var("CFLAGS").unwrap_or_default();
    println!("cargo:rustc-env=TRIBO_BENCH_CFLAGS={cflags}");
    let profile = std::env::var("PROFILE").unwrap_or_default();
    println!("cargo:rustc-env=TRIBO_BENCH_PROFILE={profile}");
}
