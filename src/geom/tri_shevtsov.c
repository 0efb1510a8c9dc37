#include "tri_shevtsov.h"

int fr_tri_shevtsov_make(fr_tri_shevtsov *r, vec3 p0, vec3 p1, vec3 p2, uint32_t prim) {
  /* double precision for the precomputation: the record is made once */
  double a[3] = {p0.x, p0.y, p0.z}, b[3] = {p1.x, p1.y, p1.z}, c[3] = {p2.x, p2.y, p2.z};
  double e1[3], e2[3], n[3];
  for (int i = 0; i < 3; i++) { e1[i] = b[i] - a[i]; e2[i] = c[i] - a[i]; }
  n[0] = e1[1] * e2[2] - e1[2] * e2[1];
  n[1] = e1[2] * e2[0] - e1[0] * e2[2];
  n[2] = e1[0] * e2[1] - e1[1] * e2[0];
  int k = 0;
  for (int i = 1; i < 3; i++)
    if (fabs(n[i]) > fabs(n[k])) k = i;
  if (n[k] == 0.0) return 0;
  int u = (k + 1) % 3, v = (k + 2) % 3;
  r->k = k;
  r->n_u = (float)(n[u] / n[k]);
  r->n_v = (float)(n[v] / n[k]);
  r->a_k = (float)a[k];
  r->axis_aligned = (n[u] == 0.0 && n[v] == 0.0);
  /* solve h - a = beta e1 + gamma e2 in the (u, v) projection */
  double det = e1[u] * e2[v] - e1[v] * e2[u];
  if (det == 0.0) return 0;
  double bu = e2[v] / det, bv = -e2[u] / det;
  double cu = -e1[v] / det, cv = e1[u] / det;
  r->b_u = (float)bu; r->b_v = (float)bv; r->a_u = (float)a[u];
  r->c_u = (float)cu; r->c_v = (float)cv; r->a_v = (float)a[v];
  r->prim = prim;
  return 1;
}
