//! Generates the PETSc bindings with bindgen from the headers pkg-config names, and
//! checks that PETSc was configured as the safe layer assumes: 32-bit `PetscInt`, real
//! double `PetscScalar` (Debian's `petsc-dev`). Anything else stops the build with what
//! was found and what to install.

use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=wrapper.h");
    let petsc = pkg_config::Config::new()
        .probe("PETSc")
        .unwrap_or_else(|e| {
            panic!(
            "fem-petsc needs PETSc's development files, found through pkg-config (`PETSc`): {e}\n\
             On Debian: apt-get install petsc-dev libclang-dev (Open MPI comes with it)"
        )
        });
    let mut builder = bindgen::Builder::default().header("wrapper.h");
    for path in &petsc.include_paths {
        builder = builder.clang_arg(format!("-I{}", path.display()));
    }
    // PETSc's pkg-config file leaves out the MPI include path
    if let Ok(mpi) = pkg_config::Config::new()
        .cargo_metadata(false)
        .probe("ompi")
    {
        for path in &mpi.include_paths {
            builder = builder.clang_arg(format!("-I{}", path.display()));
        }
    }
    let bindings = builder
        .allowlist_function("(Petsc|Vec|Mat|SNES|KSP|PC|IS)[A-Za-z0-9_]*")
        .allowlist_type("(Petsc|Vec|Mat|SNES|KSP|PC|IS|InsertMode|NormType)[A-Za-z0-9_]*")
        .allowlist_var("(PETSC_|FEM_PETSC_|ompi_mpi_)[A-Za-z0-9_]*")
        .generate()
        .unwrap_or_else(|e| {
            panic!("bindgen could not read PETSc's headers (is libclang-dev installed?): {e}")
        });
    let out =
        PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("bindings.rs");
    bindings
        .write_to_file(&out)
        .unwrap_or_else(|e| panic!("{}: {e}", out.display()));
    let text = std::fs::read_to_string(&out).unwrap_or_default();
    let int = text.contains("pub type PetscInt = ::std::os::raw::c_int;");
    let scalar = text.contains("pub type PetscScalar = PetscReal;")
        && text.contains("pub type PetscReal = f64;");
    if !int || !scalar {
        let found = |name: &str| {
            text.lines()
                .find(|l| l.starts_with(&format!("pub type {name} =")))
                .unwrap_or("not found")
                .to_string()
        };
        panic!(
            "fem-petsc assumes PETSc with 32-bit PetscInt and real double PetscScalar (Debian's petsc-dev); these headers have `{}`, `{}`, `{}`. Point pkg-config (PKG_CONFIG_PATH) at such a build.",
            found("PetscInt"),
            found("PetscScalar"),
            found("PetscReal")
        );
    }
}
