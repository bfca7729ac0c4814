//! Generates the bindings when the feature `bind` is on: the include and link flags of PETSc
//! and of MPI (Open MPI's `ompi-c`, or `mpi`) from pkg-config, bindgen over `wrapper.h`
//! (PETSc's headers and MUMPS' `dmumps_c.h`), MUMPS' `dmumps` linked.
//! Without the feature there is nothing to build, so the default workspace needs no PETSc.

#[cfg(feature = "bind")]
fn main() {
    use std::path::PathBuf;
    println!("cargo:rerun-if-changed=wrapper.h");
    let petsc = pkg_config::Config::new()
        .atleast_version("3.18")
        .probe("PETSc")
        .or_else(|_| pkg_config::probe_library("petsc"))
        .unwrap_or_else(|e| {
            panic!(
                "PETSc not found by pkg-config ({e}). On Debian: apt-get install petsc-dev \
                 libclang-dev pkg-config; elsewhere set PKG_CONFIG_PATH to the directory of PETSc.pc"
            )
        });
    let mpi = ["ompi-c", "ompi", "mpich", "mpi"]
        .iter()
        .find_map(|name| pkg_config::probe_library(name).ok())
        .unwrap_or_else(|| panic!("MPI not found by pkg-config (tried ompi-c, ompi, mpich, mpi)"));
    let mut builder = bindgen::Builder::default()
        .header("wrapper.h")
        .allowlist_function("(Petsc|Vec|Mat|KSP|PC|IS|ISLocalToGlobalMapping|MPI)_?[A-Za-z0-9_]*")
        .allowlist_function("dmumps_c")
        .allowlist_type("DMUMPS_STRUC_C")
        .allowlist_type("(Petsc|Vec|Mat|KSP|PC|IS|MPI|Insert|Norm|Scatter)_?[A-Za-z0-9_]*")
        .allowlist_var("(PETSC|MPI|ompi_mpi|Petsc|KSP|PC|MAT|VEC|NORM|INSERT|ADD)_?[A-Za-z0-9_]*")
        .allowlist_var("ompi_mpi_comm_(world|self)")
        .allowlist_var("ompi_mpi_(int|double|sum|max|min|byte)")
        .default_enum_style(bindgen::EnumVariation::ModuleConsts)
        .derive_default(true)
        .layout_tests(false)
        .generate_comments(false)
        .parse_callbacks(Box::new(bindgen::CargoCallbacks::new()));
    for dir in petsc.include_paths.iter().chain(mpi.include_paths.iter()) {
        builder = builder.clang_arg(format!("-I{}", dir.display()));
    }
    let bindings = builder
        .generate()
        .unwrap_or_else(|e| panic!("bindgen over petsc.h failed: {e}"));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    bindings
        .write_to_file(out.join("bindings.rs"))
        .expect("bindings.rs is written to OUT_DIR");
    // MUMPS (a dependency of Debian's petsc-dev, its headers beside PETSc's): PETSc links it
    // for itself; the layer calls its C interface directly
    println!("cargo:rustc-link-lib=dmumps");
    // pkg-config printed the link lines of both; the rpath lets the binaries run uninstalled.
    for dir in petsc.link_paths.iter().chain(mpi.link_paths.iter()) {
        println!("cargo:rustc-link-arg=-Wl,-rpath,{}", dir.display());
    }
}

#[cfg(not(feature = "bind"))]
fn main() {}
