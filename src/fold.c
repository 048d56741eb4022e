/* SPDX-License-Identifier: MIT */
/* Tangled from literate/fold.org: do not edit; edit the .org and run make tangle. */
/* [[file:../literate/fold.org::Fold Includes][Fold Includes]] */
#include <string.h>

#include "foldest/error.h"
#include "foldest/fold.h"
/* Fold Includes ends here */
/* [[file:../literate/fold.org::Check an accumulator][Check an accumulator]] */
/* An accumulator is usable when it has a step and sizes. */
static int fe__usable(const fe_accumulator *f)
{
    return f != NULL && f->step != NULL && f->acc_size > 0 && f->obs_size > 0;
}
/* Check an accumulator ends here */
/* [[file:../literate/fold.org::Initialise, step, merge and copy][Initialise, step, merge and copy]] */
int fe_init(const fe_accumulator *f, void *acc)
{
    if (!fe__usable(f) || acc == NULL)
        return FE_EINVAL;
    if (f->init == NULL) {
        memset(acc, 0, f->acc_size);
        return FE_OK;
    }
    return f->init(acc, f->ctx);
}

int fe_step(const fe_accumulator *f, void *acc, const void *obs)
{
    if (!fe__usable(f) || acc == NULL || obs == NULL)
        return FE_EINVAL;
    return f->step(acc, obs, f->ctx);
}

int fe_merge(const fe_accumulator *f, void *acc, const void *other)
{
    if (!fe__usable(f) || acc == NULL || other == NULL)
        return FE_EINVAL;
    if (f->merge == NULL)
        return FE_ENOTSUP;
    return f->merge(acc, other, f->ctx);
}

int fe_copy(const fe_accumulator *f, void *dst, const void *src)
{
    if (!fe__usable(f) || dst == NULL || src == NULL)
        return FE_EINVAL;
    if (f->copy != NULL)
        return f->copy(dst, src, f->ctx);
    if (dst != src)
        memcpy(dst, src, f->acc_size);
    return FE_OK;
}
/* Initialise, step, merge and copy ends here */
/* [[file:../literate/fold.org::Fold an array of observations][Fold an array of observations]] */
int fe_fold(const fe_accumulator *f, void *acc, const void *obs, size_t n,
            size_t *done)
{
    const unsigned char *z = obs;
    size_t k = 0;
    int rc = FE_OK;

    if (done != NULL)
        *done = 0;
    if (!fe__usable(f) || acc == NULL || (obs == NULL && n > 0))
        return FE_EINVAL;
    if (f->step_many != NULL && n > 0) {
        rc = f->step_many(acc, obs, n, &k, f->ctx);
    } else {
        for (; k < n; k++) {
            rc = f->step(acc, z + k * f->obs_size, f->ctx);
            if (rc != FE_OK)
                break;
        }
    }
    if (done != NULL)
        *done = k;
    return rc;
}
/* Fold an array of observations ends here */
/* [[file:../literate/fold.org::Scan an array of observations][Scan an array of observations]] */
int fe_scan_visit(const fe_accumulator *f, void *acc, const void *obs,
                  size_t n, fe_visit_fn *visit, void *visit_ctx,
                  size_t *done)
{
    const unsigned char *z = obs;
    size_t k = 0;
    int rc;

    if (done != NULL)
        *done = 0;
    if (!fe__usable(f) || acc == NULL || visit == NULL
        || (obs == NULL && n > 0))
        return FE_EINVAL;
    rc = visit(acc, 0, visit_ctx);
    while (rc == FE_OK && k < n) {
        rc = f->step(acc, z + k * f->obs_size, f->ctx);
        if (rc != FE_OK)
            break;
        k++;
        rc = visit(acc, k, visit_ctx);
    }
    if (done != NULL)
        *done = k;
    return rc;
}

struct fe__scan_buffer {
    unsigned char *out;
    size_t acc_size;
};

static int fe__scan_store(const void *acc, size_t index, void *visit_ctx)
{
    struct fe__scan_buffer *b = visit_ctx;
    memcpy(b->out + index * b->acc_size, acc, b->acc_size);
    return FE_OK;
}

int fe_scan(const fe_accumulator *f, void *acc, const void *obs, size_t n,
            void *out, size_t *done)
{
    struct fe__scan_buffer b;

    if (done != NULL)
        *done = 0;
    if (!fe__usable(f) || out == NULL)
        return FE_EINVAL;
    if (f->copy != NULL)
        return FE_ENOTSUP;
    b.out = out;
    b.acc_size = f->acc_size;
    return fe_scan_visit(f, acc, obs, n, fe__scan_store, &b, done);
}
/* Scan an array of observations ends here */
/* [[file:../literate/fold.org::Product of accumulators][Product of accumulators]] */
/* Copy component accumulations back from their spares, parts [0, k). */
static void fe__product_restore(const fe_product *p, const fe_product_acc *a,
                                size_t k)
{
    for (size_t j = 0; j < k; j++)
        (void)fe_copy(p->parts[j].acc, a->accs[j], a->spare[j]);
}

static int fe__product_init(void *acc, void *ctx)
{
    const fe_product *p = ctx;
    const fe_product_acc *a = acc;
    if (a->accs == NULL || a->spare == NULL)
        return FE_EINVAL;
    for (size_t i = 0; i < p->count; i++) {
        int rc = fe_init(p->parts[i].acc, a->accs[i]);
        if (rc != FE_OK)
            return rc;
    }
    return FE_OK;
}

static int fe__product_step(void *acc, const void *obs, void *ctx)
{
    const fe_product *p = ctx;
    const fe_product_acc *a = acc;
    const unsigned char *z = obs;
    for (size_t i = 0; i < p->count; i++) {
        const fe_accumulator *f = p->parts[i].acc;
        int rc = fe_copy(f, a->spare[i], a->accs[i]);
        if (rc == FE_OK)
            rc = f->step(a->accs[i], z + p->parts[i].obs_offset, f->ctx);
        if (rc != FE_OK) {
            fe__product_restore(p, a, i);
            return rc;
        }
    }
    return FE_OK;
}

static int fe__product_merge(void *acc, const void *other, void *ctx)
{
    const fe_product *p = ctx;
    const fe_product_acc *a = acc;
    const fe_product_acc *b = other;
    for (size_t i = 0; i < p->count; i++) {
        const fe_accumulator *f = p->parts[i].acc;
        int rc = fe_copy(f, a->spare[i], a->accs[i]);
        if (rc == FE_OK)
            rc = fe_merge(f, a->accs[i], b->accs[i]);
        if (rc != FE_OK) {
            fe__product_restore(p, a, i);
            return rc;
        }
    }
    return FE_OK;
}

static int fe__product_copy(void *dst, const void *src, void *ctx)
{
    const fe_product *p = ctx;
    const fe_product_acc *d = dst;
    const fe_product_acc *s = src;
    for (size_t i = 0; i < p->count; i++) {
        int rc = fe_copy(p->parts[i].acc, d->accs[i], s->accs[i]);
        if (rc != FE_OK)
            return rc;
    }
    return FE_OK;
}

int fe_product_accumulator(fe_accumulator *out, const fe_product *spec,
                           size_t obs_size)
{
    int merges = 1;

    if (out == NULL || spec == NULL || obs_size == 0
        || (spec->parts == NULL && spec->count > 0))
        return FE_EINVAL;
    for (size_t i = 0; i < spec->count; i++) {
        const fe_product_part *part = &spec->parts[i];
        if (!fe__usable(part->acc) || part->obs_offset > obs_size
            || part->acc->obs_size > obs_size - part->obs_offset)
            return FE_EINVAL;
        merges = merges && part->acc->merge != NULL;
    }
    memset(out, 0, sizeof *out);
    out->name = "product";
    out->acc_size = sizeof(fe_product_acc);
    out->obs_size = obs_size;
    out->init = fe__product_init;
    out->step = fe__product_step;
    out->merge = merges ? fe__product_merge : NULL;
    out->copy = fe__product_copy;
    out->ctx = (void *)spec; /* read, never written, by the functions above */
    return FE_OK;
}
/* Product of accumulators ends here */
