/*
 * report.c -- the JSON report of `getme smooth --report FILE`: what the
 * benchmark and scripts read (statistics, iterations, per-iteration
 * history for the paper's quality-over-time plots).
 */
#include "cli.h"

#include <stdio.h>

/* JSON string with the characters JSON requires escaped. */
static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; s && *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20)
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

static void json_stats(FILE *f, const getme_quality_stats *s)
{
    /* q*min is undefined (null) when no element has a free node */
    char qs[32] = "null";
    if (s->num_free > 0)
        snprintf(qs, sizeof qs, "%.17g", s->q_min_star);
    fprintf(f, "{\"elements\": %lld, \"invalid\": %lld, \"q_min_star\": %s, "
               "\"q_min\": %.17g, \"q_mean\": %.17g, \"q_max\": %.17g, "
               "\"below_0_4\": %lld, \"below_0_1\": %lld, \"histogram\": [",
            (long long)s->num_elements, (long long)s->num_invalid,
            qs, s->q_min, s->q_mean, s->q_max,
            (long long)s->num_below_04, (long long)s->num_below_01);
    for (int b = 0; b < GETME_HIST_BINS; b++)
        fprintf(f, "%s%lld", b ? ", " : "", (long long)s->histogram[b]);
    fputs("]}", f);
}

static const char *stop_name(getme_stop_reason r)
{
    switch (r) {
    case GETME_STOP_CONVERGED: return "converged";
    case GETME_STOP_MAX_ITER: return "max_iter";
    case GETME_STOP_CANCELLED: return "cancelled";
    case GETME_STOP_NOTHING_TO_DO: return "nothing_to_do";
    }
    return "unknown";
}

void cli_count_mesh(getme_mesh *mesh, cli_mesh_counts *c)
{
    c->nodes = getme_mesh_num_nodes(mesh);
    c->fixed = getme_mesh_num_fixed(mesh);
    for (int t = 0; t < GETME_NUM_TYPES; t++)
        c->elements[t] =
            getme_mesh_num_elements_of_type(mesh, (getme_elem_type)t);
}

int cli_write_report(const char *path, const char *input, const char *output,
                     const getme_params *p, const cli_mesh_counts *mesh,
                     const getme_quality_stats *before,
                     const getme_quality_stats *after, const getme_result *r,
                     const cli_history *h, const char *format_name,
                     const cli_report_extra *x)
{
    /* Through a temporary file next to it and a rename, like the mesh. */
    char tmp[4200];
    if (getme_io_tmp_path(path, tmp, sizeof tmp) != 0)
        return -1;
    FILE *f = fopen(tmp, "w");
    if (!f) {
        remove(tmp);
        return -1;
    }
    fputs("{\n  \"getme_version\": ", f);
    json_string(f, getme_version());
    fputs(",\n  \"input\": ", f);
    json_string(f, input);
    fputs(",\n  \"output\": ", f);
    json_string(f, output);
    fputs(",\n  \"format\": ", f);
    json_string(f, format_name);
    fprintf(f, ",\n  \"method\": \"%s\",\n",
            p->method == GETME_METHOD_ADAPTIVE ? "getme" : "laplace");
    fprintf(f, "  \"params\": {\"max_iter\": %d, \"tol\": %.17g, \"sigma\": %.17g, "
               "\"threshold_fraction\": %.17g, \"max_no_min_improve\": %d, \"min_tol\": %.17g, "
               "\"keep_best\": %d, \"finish\": %d, \"finish_fraction\": %.17g, "
               "\"finish_max_passes\": %d, \"corner_guard\": %d, "
               "\"corner_floor\": %.17g, \"num_threads\": %d, \"renumber\": %d},\n",
            p->max_iter, p->tol, p->sigma, p->threshold_fraction,
            p->max_no_min_improve, p->min_tol, p->keep_best, p->finish,
            p->finish_fraction, p->finish_max_passes, p->corner_guard,
            p->corner_floor, p->num_threads, p->renumber);
    fprintf(f, "  \"nodes\": %d,\n  \"fixed_nodes\": %d,\n  \"elements\": {",
            (int)mesh->nodes, (int)mesh->fixed);
    int first = 1;
    for (int t = 0; t < GETME_NUM_TYPES; t++) {
        int32_t n = mesh->elements[t];
        if (!n)
            continue;
        fprintf(f, "%s\"%s\": %d", first ? "" : ", ",
                getme_type_name((getme_elem_type)t), (int)n);
        first = 0;
    }
    fputs("},\n  \"before\": ", f);
    json_stats(f, before);
    fputs(",\n  \"after\": ", f);
    json_stats(f, after);
    if (x && x->measures_before && x->measures_after) {
        fputs(",\n  \"measures\": {\"before\": ", f);
        cli_json_measures(f, x->measures_before);
        fputs(",\n    \"after\": ", f);
        cli_json_measures(f, x->measures_after);
        fputc('}', f);
    }
    fprintf(f, ",\n  \"iterations\": {\"total\": %d, \"mean_stage\": %d, "
               "\"min_stage\": %d, \"min_cycles\": %d, \"finish_passes\": %d, "
               "\"finish_improved\": %d, \"reverted_nodes\": %d},\n",
            r->iterations, r->iterations_mean, r->iterations_min, r->cycles_min,
            r->passes_finish, (int)r->moved_finish, (int)r->reverted_nodes);
    fprintf(f, "  \"untangle\": {\"invalid\": %lld, \"sweeps\": %d, "
               "\"seconds\": %.6f},\n",
            (long long)r->num_invalid_initial, r->untangle_sweeps,
            r->untangle_seconds);
    fprintf(f, "  \"corner_sj\": {\"before\": %.17g, \"after\": %.17g},\n",
            r->corner_sj_initial, r->corner_sj);
    if (x && x->ho_before && x->ho_after && x->ho_before->n > 0)
        fprintf(f, "  \"second_order\": {\"elements\": %ld, "
                   "\"jacobian_ratio\": {\"before\": %.17g, \"after\": %.17g}, "
                   "\"worst_element\": {\"before\": %lld, \"after\": %lld}},\n",
                (long)x->ho_before->n, x->ho_before->ratio, x->ho_after->ratio,
                x->ho_before->id, x->ho_after->id);
    if (x && x->doc && x->worst && x->worst_free) {
        fputs("  \"worst_elements\": ", f);
        cli_json_worst(f, x->doc, x->worst);
        fputs(",\n  \"worst_free_elements\": ", f);
        cli_json_worst(f, x->doc, x->worst_free);
        fputs(",\n", f);
    }
    fprintf(f, "  \"seconds\": %.6f,\n  \"stop_reason\": \"%s\",\n",
            r->seconds, stop_name(r->stop_reason));
    fputs("  \"history\": [", f);
    for (int i = 0; i < h->count; i++) {
        const getme_progress *e = &h->items[i];
        fprintf(f, "%s\n    {\"iteration\": %d, \"stage\": %d, \"cycle\": %d, "
                   "\"q_min_star\": %.17g, \"q_mean\": %.17g, \"threshold\": %.17g, "
                   "\"transformed\": %d, \"relaxed\": %d, \"elapsed\": %.6f}",
                i ? "," : "", e->iteration, (int)e->stage, e->cycle,
                e->q_min_star, e->q_mean, e->threshold, (int)e->num_transformed,
                (int)e->num_relaxed, e->elapsed);
    }
    fputs("\n  ]\n}\n", f);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad) {
        remove(tmp);
        return -1;
    }
    return getme_io_commit(tmp, path);
}
