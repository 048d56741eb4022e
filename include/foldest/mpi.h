/* SPDX-License-Identifier: MIT */
/* Tangled from literate/mpi.org: do not edit; edit the .org and run make tangle. */
/* [[file:../../literate/mpi.org::MPI Helper Declarations][MPI Helper Declarations]] */
#ifndef FOLDEST_MPI_H
#define FOLDEST_MPI_H

/* Optional, header-only: include it in MPI programs (compiled with mpicc).
   libfoldest itself never uses MPI, and foldest.h does not include this. */
#include <mpi.h>
#include <stdint.h>
#include <string.h>

#include "foldest.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The MPI handles of one reduction: the datatype of one cell and the
   (non-commutative) operation merging two cells.  Create with the
   <name>_reduction function made by FE_MPI_DEFINE_REDUCTION, free with
   fe_mpi_reduction_free before MPI_Finalize. */
typedef struct fe_mpi_reduction {
    MPI_Datatype type;
    MPI_Op op;
} fe_mpi_reduction;
/* MPI Helper Declarations ends here */
/* [[file:../../literate/mpi.org::Combine two cells][Combine two cells]] */
/* Internal: (acc, done, status, rank) <- itself o (other, ...), the rule
   of the cells: a refusal on the left discards the right. */
static inline void fe__mpi_combine(const fe_accumulator *f, void *acc,
                                   uint64_t *done, int *status, int *rank,
                                   const void *other, uint64_t other_done,
                                   int other_status, int other_rank,
                                   int other_first)
{
    int rc;
    if (*status != FE_OK)
        return;
    rc = fe_merge(f, acc, other);
    if (rc != FE_OK) {
        *status = rc;
        *rank = other_first;
        return;
    }
    *done += other_done;
    *status = other_status;
    *rank = other_rank;
}
/* Combine two cells ends here */
/* [[file:../../literate/mpi.org::Create and free the MPI handles][Create and free the MPI handles]] */
/* fe_mpi_reduction_create: the datatype (cell_size contiguous bytes) and
   the operation `fn`, declared non-commutative.  Used by the functions
   FE_MPI_DEFINE_REDUCTION makes.  FE_EIO when MPI refuses. */
static inline int fe_mpi_reduction_create(fe_mpi_reduction *r,
                                          size_t cell_size,
                                          MPI_User_function *fn)
{
    if (r == NULL || fn == NULL || cell_size == 0 || cell_size > INT32_MAX)
        return FE_EINVAL;
    if (MPI_Type_contiguous((int)cell_size, MPI_BYTE, &r->type) != MPI_SUCCESS)
        return FE_EIO;
    if (MPI_Type_commit(&r->type) != MPI_SUCCESS
        || MPI_Op_create(fn, 0 /* not commutative */, &r->op) != MPI_SUCCESS) {
        MPI_Type_free(&r->type);
        return FE_EIO;
    }
    return FE_OK;
}

/* fe_mpi_reduction_free: release the handles (call before MPI_Finalize). */
static inline void fe_mpi_reduction_free(fe_mpi_reduction *r)
{
    if (r == NULL)
        return;
    MPI_Op_free(&r->op);
    MPI_Type_free(&r->type);
}
/* Create and free the MPI handles ends here */
/* [[file:../../literate/mpi.org::Record a rank's outcome in its cell][Record a rank's outcome in its cell]] */
/* name##_cell_record(c, rc, done): the outcome of the rank's fold; the
   first refusal is kept.  Ends the definitions (swallows the semicolon). */
#define FE__MPI_DEFINE_CELL_RECORD(name)                                     \
    static inline void name##_cell_record(name##_cell *c, int rc,            \
                                          size_t done)                       \
    {                                                                        \
        if (c->status != FE_OK)                                              \
            return;                                                          \
        c->done = (uint64_t)done;                                            \
        c->status = rc;                                                      \
        c->rank = rc != FE_OK ? c->first : -1;                               \
    }                                                                        \
    typedef int name##_defined_ /* swallow the caller's semicolon */
/* Record a rank's outcome in its cell ends here */
/* [[file:../../literate/mpi.org::Define a reduction for one accumulation type][Define a reduction for one accumulation type]] */
#define FE_MPI_DEFINE_REDUCTION(name, type, accumulator)                     \
    typedef struct name##_cell {                                             \
        type acc;           /* the accumulation (flat) */                    \
        uint64_t done;      /* observations folded into acc */               \
        int status;         /* FE_OK, or the first refusal's code */         \
        int rank;           /* rank of that refusal; -1 when none */         \
        int first;          /* first rank this cell covers */                \
    } name##_cell;                                                           \
                                                                             \
    static void name##_op(void *in, void *inout, int *len,                   \
                          MPI_Datatype *datatype)                            \
    {                                                                        \
        const fe_accumulator fe_f_ = (accumulator);                          \
        unsigned char *fe_in_ = in, *fe_io_ = inout;                         \
        (void)datatype;                                                      \
        for (int fe_i_ = 0; fe_i_ < *len; fe_i_++) {                         \
            name##_cell fe_l_, fe_r_;                                        \
            memcpy(&fe_l_, fe_in_ + (size_t)fe_i_ * sizeof fe_l_,            \
                   sizeof fe_l_);                                            \
            memcpy(&fe_r_, fe_io_ + (size_t)fe_i_ * sizeof fe_r_,            \
                   sizeof fe_r_);                                            \
            fe__mpi_combine(&fe_f_, &fe_l_.acc, &fe_l_.done,                 \
                            &fe_l_.status, &fe_l_.rank, &fe_r_.acc,          \
                            fe_r_.done, fe_r_.status, fe_r_.rank,            \
                            fe_r_.first);                                    \
            memcpy(fe_io_ + (size_t)fe_i_ * sizeof fe_l_, &fe_l_,            \
                   sizeof fe_l_);                                            \
        }                                                                    \
    }                                                                        \
                                                                             \
    static inline int name##_reduction(fe_mpi_reduction *r)                  \
    {                                                                        \
        const fe_accumulator fe_f_ = (accumulator);                          \
        if (fe_f_.copy != NULL || fe_f_.acc_size != sizeof(type)             \
            || fe_f_.merge == NULL)                                          \
            return FE_ENOTSUP;                                               \
        return fe_mpi_reduction_create(r, sizeof(name##_cell), name##_op);   \
    }                                                                        \
                                                                             \
    static inline int name##_cell_init(name##_cell *c, int rank)             \
    {                                                                        \
        const fe_accumulator fe_f_ = (accumulator);                          \
        memset(c, 0, sizeof *c);                                             \
        c->rank = -1;                                                        \
        c->first = rank;                                                     \
        c->status = fe_init(&fe_f_, &c->acc);                                \
        if (c->status != FE_OK)                                              \
            c->rank = rank;                                                  \
        return c->status;                                                    \
    }                                                                        \
                                                                             \
    FE__MPI_DEFINE_CELL_RECORD(name)
/* Define a reduction for one accumulation type ends here */
/* [[file:../../literate/mpi.org::Define a reduction for accumulations bound to storage][Define a reduction for accumulations bound to storage]] */
#define FE_MPI_DEFINE_BOUND_REDUCTION(name, type, accumulator, capacity,     \
                                      rebind)                                \
    typedef struct name##_cell {                                             \
        type acc;           /* points into storage[] once rebound */         \
        double storage[capacity];                                            \
        uint64_t done;      /* observations folded into acc */               \
        int status;         /* FE_OK, or the first refusal's code */         \
        int rank;           /* rank of that refusal; -1 when none */         \
        int first;          /* first rank this cell covers */                \
    } name##_cell;                                                           \
                                                                             \
    static inline int name##_cell_rebind(name##_cell *c)                     \
    {                                                                        \
        return rebind(&c->acc, c->storage);                                  \
    }                                                                        \
                                                                             \
    static void name##_op(void *in, void *inout, int *len,                   \
                          MPI_Datatype *datatype)                            \
    {                                                                        \
        const fe_accumulator fe_f_ = (accumulator);                          \
        unsigned char *fe_in_ = in, *fe_io_ = inout;                         \
        (void)datatype;                                                      \
        for (int fe_i_ = 0; fe_i_ < *len; fe_i_++) {                         \
            name##_cell fe_l_, fe_r_;                                        \
            int fe_rc_;                                                      \
            memcpy(&fe_l_, fe_in_ + (size_t)fe_i_ * sizeof fe_l_,            \
                   sizeof fe_l_);                                            \
            memcpy(&fe_r_, fe_io_ + (size_t)fe_i_ * sizeof fe_r_,            \
                   sizeof fe_r_);                                            \
            if (fe_l_.status == FE_OK) {                                     \
                fe_rc_ = name##_cell_rebind(&fe_l_);                         \
                if (fe_rc_ == FE_OK)                                         \
                    fe_rc_ = name##_cell_rebind(&fe_r_);                     \
                if (fe_rc_ == FE_OK)                                         \
                    fe__mpi_combine(&fe_f_, &fe_l_.acc, &fe_l_.done,         \
                                    &fe_l_.status, &fe_l_.rank, &fe_r_.acc,  \
                                    fe_r_.done, fe_r_.status, fe_r_.rank,    \
                                    fe_r_.first);                            \
                else if (fe_r_.status != FE_OK) {                            \
                    fe_l_.status = fe_r_.status;  /* never bound: its */     \
                    fe_l_.rank = fe_r_.rank;      /* own refusal */          \
                } else {                                                     \
                    fe_l_.status = fe_rc_;        /* cannot be read */       \
                    fe_l_.rank = fe_r_.first;                                \
                }                                                            \
            }                                                                \
            memcpy(fe_io_ + (size_t)fe_i_ * sizeof fe_l_, &fe_l_,            \
                   sizeof fe_l_);                                            \
        }                                                                    \
    }                                                                        \
                                                                             \
    static inline int name##_reduction(fe_mpi_reduction *r)                  \
    {                                                                        \
        const fe_accumulator fe_f_ = (accumulator);                          \
        if (fe_f_.acc_size != sizeof(type) || fe_f_.merge == NULL)           \
            return FE_ENOTSUP;                                               \
        return fe_mpi_reduction_create(r, sizeof(name##_cell), name##_op);   \
    }                                                                        \
                                                                             \
    static inline void name##_cell_init(name##_cell *c, int rank)            \
    {                                                                        \
        memset(c, 0, sizeof *c);                                             \
        c->rank = -1;                                                        \
        c->first = rank;                                                     \
        c->status = FE_OK;                                                   \
    }                                                                        \
                                                                             \
    FE__MPI_DEFINE_CELL_RECORD(name)
/* Define a reduction for accumulations bound to storage ends here */
/* [[file:../../literate/mpi.org::Rebind the accumulations that travel in cells][Rebind the accumulations that travel in cells]] */
/* fe_mpi_rebind_lsq: a->g <- storage (the whole layout of fe_lsq_init). */
static inline int fe_mpi_rebind_lsq(fe_lsq *a, double *storage)
{
    if (a == NULL || storage == NULL)
        return FE_EINVAL;
    a->g = storage;
    return FE_OK;
}

/* fe_mpi_rebind_discover: fe_discover_rebind. */
static inline int fe_mpi_rebind_discover(fe_discover_acc *a, double *storage)
{
    return fe_discover_rebind(a, storage);
}
/* Rebind the accumulations that travel in cells ends here */
/* [[file:../../literate/mpi.org::Reduce cells across ranks][Reduce cells across ranks]] */
/* fe_mpi_reduce: result (on `root` only) <- cell of rank 0 o cell of rank 1
   o ... (rank order).  `cell` and `result` are name_cell objects of the
   reduction `r`; `result` may be NULL on other ranks.  Collective: every
   rank of `comm` must call it, whatever its own fold returned. */
static inline int fe_mpi_reduce(const fe_mpi_reduction *r, const void *cell,
                                void *result, int root, MPI_Comm comm)
{
    if (r == NULL || cell == NULL)
        return FE_EINVAL;
    return MPI_Reduce(cell, result, 1, r->type, r->op, root, comm)
                   == MPI_SUCCESS
               ? FE_OK
               : FE_EIO;
}

/* fe_mpi_allreduce: the same reduction, with the result on every rank. */
static inline int fe_mpi_allreduce(const fe_mpi_reduction *r,
                                   const void *cell, void *result,
                                   MPI_Comm comm)
{
    if (r == NULL || cell == NULL || result == NULL)
        return FE_EINVAL;
    return MPI_Allreduce(cell, result, 1, r->type, r->op, comm)
                   == MPI_SUCCESS
               ? FE_OK
               : FE_EIO;
}

#ifdef __cplusplus
}
#endif

#endif /* FOLDEST_MPI_H */
/* Reduce cells across ranks ends here */
