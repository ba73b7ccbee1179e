/* The scene tree: positions and paths, duplicate keys, syntax errors,
 * unknown keys with suggestions, typed getters and defaults, --set
 * overrides, and a write/load round trip. */
#include "test_util.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sph/node.h"

static const char *doc = "name: column\n"
                         "materials:\n"
                         "  rubber:\n"
                         "    density: 1100\n"
                         "    poisson_ratio: 0.45\n"
                         "bodies:\n"
                         "  - name: a\n"
                         "    count: [5, 25, 5]\n"
                         "  - name: b\n"
                         "    label: \"0.5\"\n"
                         "flag: yes\n";

static sph_node *load(const char *text) {
  sph_node *root = NULL;
  sph_error err;
  ck_assert_int_eq(sph_node_load_string(&root, text, "t.yaml", &err), SPH_OK);
  return root;
}

START_TEST(positions_and_paths) {
  sph_node *root = load(doc);
  sph_node *rubber =
      sph_node_child(sph_node_child(root, "materials"), "rubber");
  ck_assert_ptr_nonnull(rubber);
  sph_node *nu = sph_node_child(rubber, "poisson_ratio");
  ck_assert_str_eq(nu->path, "materials.rubber.poisson_ratio");
  ck_assert_int_eq(nu->line, 5);
  ck_assert_int_eq(nu->col, 5);
  ck_assert_str_eq(nu->file, "t.yaml");
  sph_node *bodies = sph_node_child(root, "bodies");
  ck_assert_int_eq(bodies->kind, SPH_NODE_SEQ);
  ck_assert_uint_eq(bodies->count, 2);
  sph_node *count = sph_node_child(bodies->items[0], "count");
  ck_assert_str_eq(count->path, "bodies[0].count");
  ck_assert_str_eq(count->items[1]->value, "25");
  ck_assert_int_eq(count->items[1]->line, 8);
  ck_assert_int_eq(sph_node_child(bodies->items[1], "label")->quoted, 1);
  sph_node_destroy(root);
}
END_TEST

START_TEST(duplicate_key_is_an_error) {
  sph_node *root = NULL;
  sph_error err;
  ck_assert_int_eq(
      sph_node_load_string(&root, "a: 1\nb:\n  c: 2\n  c: 3\n", "d.yaml", &err),
      SPH_ERR_DUPLICATE_KEY);
  ck_assert_ptr_null(root);
  ck_assert_int_eq(err.line, 4);
  ck_assert_int_eq(err.col, 3);
  ck_assert_str_eq(err.key, "c");
  ck_assert_ptr_nonnull(strstr(err.message, "first given on line 3"));
}
END_TEST

START_TEST(syntax_error_has_a_location) {
  sph_node *root = NULL;
  sph_error err;
  ck_assert_int_eq(
      sph_node_load_string(&root, "a: [1, 2\nb: 3\n", "s.yaml", &err),
      SPH_ERR_SYNTAX);
  ck_assert_str_eq(err.file, "s.yaml");
  ck_assert_int_gt(err.line, 0);
  ck_assert_ptr_nonnull(strstr(err.message, "YAML syntax"));
  ck_assert_int_eq(sph_node_load_string(&root, "", "e.yaml", &err),
                   SPH_ERR_SYNTAX);
  ck_assert_ptr_nonnull(strstr(err.message, "empty"));
  ck_assert_int_eq(sph_node_load_file(&root, "/nonexistent/x.yaml", &err),
                   SPH_ERR_IO);
  ck_assert_str_eq(err.file, "/nonexistent/x.yaml");
}
END_TEST

START_TEST(unknown_key_suggests) {
  sph_node *root = load("density: 1\npoisson: 0.3\n");
  static const char *const allowed[] = {"density", "poisson_ratio",
                                        "youngs_modulus", NULL};
  sph_error err;
  ck_assert_int_eq(sph_node_check_keys(root, allowed, &err),
                   SPH_ERR_UNKNOWN_KEY);
  ck_assert_str_eq(err.key, "poisson");
  ck_assert_int_eq(err.line, 2);
  ck_assert_ptr_nonnull(strstr(err.message, "did you mean 'poisson_ratio'"));
  sph_node_destroy(root);
  root = load("zzzzzz: 1\n");
  ck_assert_int_eq(sph_node_check_keys(root, allowed, &err),
                   SPH_ERR_UNKNOWN_KEY);
  ck_assert_ptr_nonnull(strstr(err.message, "allowed: density"));
  sph_node_destroy(root);
  ck_assert_uint_eq(sph_edit_distance("kitten", "sitting"), 3);
  ck_assert_uint_eq(sph_edit_distance("", "abc"), 3);
}
END_TEST

START_TEST(typed_getters) {
  sph_node *root = load("x: 1.5e3\nn: 7\nf: 2.5\ns: abc\nq: \"3\"\n"
                        "b: off\nv: [1, 2, 3]\nm: {a: 1}\n");
  sph_error err;
  double d;
  long n;
  int b;
  const char *s;
  ck_assert_int_eq(sph_node_get_double(root, "x", 1, 0, &d, &err), SPH_OK);
  ck_assert_double_eq(d, 1500.0);
  ck_assert_int_eq(sph_node_get_int(root, "n", 1, 0, &n, &err), SPH_OK);
  ck_assert_int_eq(n, 7);
  ck_assert_int_eq(sph_node_get_int(root, "f", 1, 0, &n, &err), SPH_ERR_TYPE);
  ck_assert_int_eq(sph_node_get_double(root, "s", 1, 0, &d, &err),
                   SPH_ERR_TYPE);
  ck_assert_ptr_nonnull(strstr(err.message, "expected a number, got 'abc'"));
  ck_assert_str_eq(err.key, "s");
  ck_assert_int_eq(sph_node_get_double(root, "q", 1, 0, &d, &err),
                   SPH_ERR_TYPE);
  ck_assert_ptr_nonnull(strstr(err.message, "quoted"));
  ck_assert_int_eq(sph_node_get_double(root, "m", 1, 0, &d, &err),
                   SPH_ERR_TYPE);
  ck_assert_ptr_nonnull(strstr(err.message, "got a mapping"));
  ck_assert_int_eq(sph_node_get_bool(root, "b", 1, 1, &b, &err), SPH_OK);
  ck_assert_int_eq(b, 0);
  ck_assert_int_eq(sph_node_get_string(root, "s", 1, NULL, &s, &err), SPH_OK);
  ck_assert_str_eq(s, "abc");
  double v[3];
  ck_assert_int_eq(sph_node_get_doubles(root, "v", 1, 3, v, NULL, &err),
                   SPH_OK);
  ck_assert_double_eq(v[2], 3.0);
  ck_assert_int_eq(sph_node_get_doubles(root, "v", 1, 2, v, NULL, &err),
                   SPH_ERR_TYPE);
  size_t got = 3;
  ck_assert_int_eq(sph_node_get_doubles(root, "v", 1, 0, v, &got, &err),
                   SPH_OK);
  ck_assert_uint_eq(got, 3);
  ck_assert_int_eq(sph_node_get_double(root, "missing", 1, 0, &d, &err),
                   SPH_ERR_MISSING_KEY);
  ck_assert_str_eq(err.key, "missing");
  sph_node *m;
  ck_assert_int_eq(sph_node_get_map(root, "m", 1, &m, &err), SPH_OK);
  ck_assert_int_eq(sph_node_get_double(m, "zz", 1, 0, &d, &err),
                   SPH_ERR_MISSING_KEY);
  ck_assert_str_eq(err.key, "m.zz");
  sph_node_destroy(root);
}
END_TEST

START_TEST(defaults_are_inserted_and_written) {
  sph_node *root = load("kernel: {type: cubic}\n");
  sph_node *k = sph_node_child(root, "kernel");
  sph_error err;
  double h;
  ck_assert_int_eq(sph_node_get_double(k, "h_over_dp", 0, 1.3, &h, &err),
                   SPH_OK);
  ck_assert_double_eq(h, 1.3);
  sph_node *d = sph_node_child(k, "h_over_dp");
  ck_assert_ptr_nonnull(d);
  ck_assert_int_eq(d->is_default, 1);
  ck_assert_str_eq(d->value, "1.3");
  ck_assert_str_eq(d->path, "kernel.h_over_dp");
  char *buf = NULL;
  size_t len = 0;
  FILE *f = open_memstream(&buf, &len);
  ck_assert_int_eq(sph_node_write(root, f, &err), SPH_OK);
  fclose(f);
  ck_assert_ptr_nonnull(strstr(buf, "h_over_dp: 1.3"));
  free(buf);
  sph_node_destroy(root);
}
END_TEST

START_TEST(set_overrides) {
  sph_node *root = load(doc);
  sph_error err;
  ck_assert_int_eq(
      sph_node_set(root, "materials.rubber.poisson_ratio=0.499", &err), SPH_OK);
  sph_node *nu = sph_node_child(
      sph_node_child(sph_node_child(root, "materials"), "rubber"),
      "poisson_ratio");
  ck_assert_str_eq(nu->value, "0.499");
  ck_assert_str_eq(nu->file, "<command line>");
  ck_assert_str_eq(nu->path, "materials.rubber.poisson_ratio");
  ck_assert_int_eq(sph_node_set(root, "bodies.0.count=[9,49,9]", &err), SPH_OK);
  sph_node *count =
      sph_node_child(sph_node_child(root, "bodies")->items[0], "count");
  ck_assert_int_eq(count->kind, SPH_NODE_SEQ);
  ck_assert_str_eq(count->items[1]->value, "49");
  ck_assert_str_eq(count->items[1]->path, "bodies[0].count[1]");
  ck_assert_int_eq(sph_node_set(root, "method.jst.eps4_J=0.03125", &err),
                   SPH_OK);
  ck_assert_str_eq(
      sph_node_child(sph_node_child(sph_node_child(root, "method"), "jst"),
                     "eps4_J")
          ->value,
      "0.03125");
  ck_assert_int_eq(sph_node_set(root, "bodies.5.name=x", &err), SPH_ERR_RANGE);
  ck_assert_int_eq(sph_node_set(root, "name.sub=1", &err), SPH_ERR_TYPE);
  ck_assert_int_eq(sph_node_set(root, "novalue", &err), SPH_ERR_ARG);
  ck_assert_int_eq(sph_node_set(root, "=3", &err), SPH_ERR_ARG);
  ck_assert_int_eq(sph_node_set(root, "a=[1,", &err), SPH_ERR_SYNTAX);
  sph_node_destroy(root);
}
END_TEST

static int tree_equal(const sph_node *a, const sph_node *b) {
  if (a->kind != b->kind || a->count != b->count)
    return 0;
  if (a->kind == SPH_NODE_SCALAR)
    return strcmp(a->value, b->value) == 0;
  for (size_t i = 0; i < a->count; ++i) {
    if (a->kind == SPH_NODE_MAP && strcmp(a->keys[i], b->keys[i]))
      return 0;
    if (!tree_equal(a->items[i], b->items[i]))
      return 0;
  }
  return 1;
}

START_TEST(write_load_round_trip) {
  sph_node *root = load("a: 1\nlist:\n  - {name: x, v: [1, 2]}\n  - name: y\n"
                        "    sub: {k: \"two words: here\"}\nempty: {}\n"
                        "s: \"#not a comment\"\nneg: -3.5\n"
                        "expr: \"sin(pi*y/(2*6))\"\n");
  char *buf = NULL;
  size_t len = 0;
  sph_error err;
  FILE *f = open_memstream(&buf, &len);
  ck_assert_int_eq(sph_node_write(root, f, &err), SPH_OK);
  fclose(f);
  sph_node *again = NULL;
  ck_assert_int_eq(sph_node_load_string(&again, buf, "w.yaml", &err), SPH_OK);
  ck_assert_msg(tree_equal(root, again), "round trip differs:\n%s", buf);
  free(buf);
  sph_node_destroy(root);
  sph_node_destroy(again);
}
END_TEST

int main(void) {
  Suite *s = suite_create("node");
  TCase *tc = tcase_create("node");
  tcase_add_test(tc, positions_and_paths);
  tcase_add_test(tc, duplicate_key_is_an_error);
  tcase_add_test(tc, syntax_error_has_a_location);
  tcase_add_test(tc, unknown_key_suggests);
  tcase_add_test(tc, typed_getters);
  tcase_add_test(tc, defaults_are_inserted_and_written);
  tcase_add_test(tc, set_overrides);
  tcase_add_test(tc, write_load_round_trip);
  suite_add_tcase(s, tc);
  return sph_test_run(s);
}
