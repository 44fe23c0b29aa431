/* The PETSc headers fem-petsc binds (bindgen). PETSC_INFINITY is a macro of an
 * expression, which bindgen drops: a constant carries its value. */
#include <petscsnes.h>
#include <petscmat.h>
static const PetscReal FEM_PETSC_INFINITY = PETSC_INFINITY;
