/*
 * server/explain_text.c — the render plan as a short text table for a terminal
 * (`umbra-render --explain` when stdout is one; piped, the CLI prints the JSON of
 * api/plan_json.c). Read from the renderer's description of the plan (umbra/rnd_plan.h): the
 * reasons are shortened here, the JSON has them whole.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "explain_text.h"
#include "umbra/rnd_plan.h"

static void head(FILE *f, const struct rnd_plan_info *in)
{
	fprintf(f, "render plan: %ux%u, %u view%s (%ux%u sheet), %u objects, %u lights; planned in %.2f ms\n", in->width,
	        in->height, in->views, in->views == 1 ? "" : "s", in->columns, in->rows, in->objects, in->lights, in->plan_ms);
	fprintf(f, "memory: %.1f MB device + %.1f MB host (largest allocation %.1f MB)\n", in->estimate.device_bytes / 1e6,
	        in->estimate.host_bytes / 1e6, in->estimate.largest_allocation / 1e6);
	fprintf(f, "shadow maps drawn %u (cached %u), %.2f Mtexel, %llu caster triangles; camera triangles %llu; "
	        "estimate %.1f ms\n", in->maps_drawn, in->maps_cached, in->texels_drawn / 1e6,
	        (unsigned long long)in->shadow_triangles, (unsigned long long)in->camera_triangles, in->estimate_ms);
	if (in->env_directions || in->env_weighed)
		fprintf(f, "environment: %u shadow directions drawn as maps, %u below the %s only weighed\n", in->env_directions,
		        in->env_weighed, in->env_ground ? "ground" : "horizon");
	if (in->analyzed)
		fprintf(f, "measured: plan %.2f, upload %.2f, shadow %.2f, main %.2f, readback %.2f ms; %u maps drawn, %u reused, "
		        "%u submits\n", in->plan_ms, in->actual.upload_ms, in->actual.shadow_ms, in->actual.main_ms,
		        in->actual.readback_ms, in->actual.shadow_maps_rendered, in->actual.shadow_maps_reused, in->actual.submits);
}

static void maps(FILE *f, const struct rnd_plan *plan, uint32_t n)
{
	if (!n) return;
	fprintf(f, "\n%-5s %-11s %-9s %5s %6s %6s %-5s %-10s %9s  %s\n", "light", "type", "kind", "tiles", "res", "asked",
	        "filt", "state", "est ms", "size");
	for (uint32_t k = 0; k < n; k++) {
		struct rnd_plan_map_info m;
		rnd_plan_map(plan, k, &m);
		fprintf(f, "%-5u %-11s %-9s %5u %6u %6u %-5s %-10s %9.2f  %s%s%s\n", m.light, m.light_type, m.kind, m.tiles,
		        m.resolution, m.asked, m.filter, m.analyzed ? (m.hit ? "hit" : m.key ? "drawn" : m.state) : m.state,
		        m.estimate_ms, m.size, m.fitted[0] ? "; " : "", m.fitted);
	}
}

static void objects(FILE *f, const struct rnd_plan *plan, uint32_t n)
{
	if (!n) return;
	fprintf(f, "\n%-6s %-8s %9s %9s %-5s  %s\n", "object", "shape", "tris", "camera", "casts", "detail / why not cast");
	for (uint32_t i = 0; i < n; i++) {
		struct rnd_plan_object_info o;
		rnd_plan_object(plan, i, &o);
		fprintf(f, "%-6u %-8s %9llu %9llu %-5s  %s%s%s\n", i, o.shape, (unsigned long long)o.triangles,
		        (unsigned long long)o.camera_triangles, o.casts ? "yes" : "no", o.detail, o.casts ? "" : "; ",
		        o.casts ? "" : o.cast_why);
		if (o.caster_triangles)
			fprintf(f, "%-6s %-8s %9llu %9s %-5s  caster level: error %g, drawn by %u environment maps\n", "",
			        "", (unsigned long long)o.caster_triangles, "", "", (double)o.caster_error, o.caster_maps);
	}
}

static void passes(FILE *f, const struct rnd_plan *plan, uint32_t n)
{
	struct rnd_plan_pass_info *p = calloc(n ? n : 1, sizeof *p);
	if (!p) return;
	rnd_plan_passes(plan, p, n);
	fprintf(f, "\n%-4s %-11s %4s %4s %6s %10s %9s  %s\n", "step", "pass", "view", "map", "res", "triangles", "est ms",
	        "note");
	for (uint32_t i = 0; i < n; i++) {
		char view[12] = "-", map[12] = "-", res[12] = "";
		if (p[i].view >= 0) snprintf(view, sizeof view, "%d", p[i].view);
		if (p[i].map >= 0) snprintf(map, sizeof map, "%d", p[i].map);
		if (p[i].resolution) snprintf(res, sizeof res, "%u", p[i].resolution);
		fprintf(f, "%-4u %-11s %4s %4s %6s %10llu %9.2f  %s\n", i, p[i].pass, view, map, res,
		        (unsigned long long)p[i].triangles, p[i].estimate_ms, p[i].note);
	}
	free(p);
}

static void views(FILE *f, const struct rnd_plan *plan, uint32_t n)
{
	fprintf(f, "\n%-4s %10s %5s %8s %-7s %-4s %-5s %-5s %9s  %s\n", "view", "camera tri", "maps", "Mtexel", "contact",
	        "env", "vis", "pixel", "est ms", "visibility pass");
	for (uint32_t v = 0; v < n; v++) {
		struct rnd_plan_view_info w;
		rnd_plan_view(plan, v, &w);
		fprintf(f, "%-4u %10llu %5u %8.2f %-7s %-4s %-5s %-5s %9.2f  %s", v, (unsigned long long)w.camera_triangles,
		        w.maps_drawn, w.texels_drawn / 1e6, w.contact ? "yes" : "no", w.env_pass ? "pass" : "no",
		        w.visibility ? "yes" : "no", w.pixel_shading ? "yes" : "no",
		        w.shadow_estimate_ms + w.main_estimate_ms, w.visibility_why);
		if (w.analyzed) fprintf(f, "; measured shadow %.2f, main %.2f ms, %u band%s", w.shadow_ms, w.main_ms, w.bands,
		                        w.bands == 1 ? "" : "s");
		fputc('\n', f);
	}
}

void srv_explain_text(FILE *f, const struct rnd_plan *plan)
{
	struct rnd_plan_info in;
	rnd_plan_info(plan, &in);
	head(f, &in);
	maps(f, plan, in.maps);
	views(f, plan, in.views);
	objects(f, plan, in.objects);
	passes(f, plan, in.passes);
}
