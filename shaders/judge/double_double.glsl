// Double-double arithmetic in GLSL: x + y of a dvec2 is the value, |y| at
// most half an ulp of x. It is bench/numerics/double_double.h operation for
// operation (the same error-free transformations in the same order, the
// same fix-ups of special values), so that on a device whose float64 add,
// multiply and divide are IEEE's it gives the host's results bit for
// bit: tests/device_judge_test.cc holds the two equal. Every intermediate
// is `precise`: nothing may be fused or reordered.

bool dd_finite(double x) { return !isnan(x) && !isinf(x); }

// s + e == a + b exactly.
dvec2 dd_two_sum(double a, double b) {
  precise double s = a + b;
  precise double bb = s - a;
  precise double e = (a - (s - bb)) + (b - bb);
  return dvec2(s, e);
}

// The same where |a| >= |b| or a == 0.
dvec2 dd_fast_two_sum(double a, double b) {
  precise double s = a + b;
  precise double e = b - (s - a);
  return dvec2(s, e);
}

// p + e == a * b exactly (barring underflow), from products and sums
// alone: Dekker's product of Veltkamp's halves. The host takes the error
// from an fma; both are exact, so they agree, but a device may carry out
// GLSL's fma as a product and a sum (lavapipe does), and the splitting
// needs no fma at all. Exact for |a|, |b| below 2^995, beyond any depth
// or constant here.
dvec2 dd_split(double a) {
  precise double c = 134217729.0lf * a;  // 2^27 + 1
  precise double high = c - (c - a);
  precise double low = a - high;
  return dvec2(high, low);
}
dvec2 dd_two_product(double a, double b) {
  precise double p = a * b;
  dvec2 x = dd_split(a);
  dvec2 y = dd_split(b);
  precise double e = ((x.x * y.x - p) + x.x * y.y + x.y * y.x) + x.y * y.y;
  return dvec2(p, e);
}

dvec2 dd(double x) { return dvec2(x, 0.0lf); }
dvec2 dd_neg(dvec2 a) { return -a; }

dvec2 dd_add(dvec2 a, dvec2 b) {
  dvec2 s = dd_two_sum(a.x, b.x);
  dvec2 t = dd_two_sum(a.y, b.y);
  precise double e = s.y + t.x;
  dvec2 s2 = dd_fast_two_sum(s.x, e);
  precise double e2 = s2.y + t.y;
  dvec2 s3 = dd_fast_two_sum(s2.x, e2);
  return dd_finite(s.x) ? s3 : dvec2(s.x, 0.0lf);
}

dvec2 dd_sub(dvec2 a, dvec2 b) { return dd_add(a, dd_neg(b)); }

dvec2 dd_mul(dvec2 a, dvec2 b) {
  dvec2 p = dd_two_product(a.x, b.x);
  precise double cross = a.x * b.y + a.y * b.x;
  precise double e = p.y + cross;
  dvec2 p2 = dd_fast_two_sum(p.x, e);
  return dd_finite(p.x) ? p2 : dvec2(p.x, 0.0lf);
}

// Joldes, Muller and Popescu's DWDivDW2, as the host's operator/.
dvec2 dd_div(dvec2 a, dvec2 b) {
  precise double q1 = a.x / b.x;
  dvec2 product = dd_two_product(b.x, q1);
  precise double bq_lo_term = b.y * q1;
  dvec2 s = dd_fast_two_sum(product.x, bq_lo_term);
  precise double carried = s.y + product.y;
  dvec2 bq = dd_fast_two_sum(s.x, carried);
  dvec2 rest = dd_two_sum(a.x, -bq.x);
  precise double rest_sum = rest.x + ((rest.y - bq.y) + a.y);
  precise double q2 = rest_sum / b.x;
  dvec2 q = dd_fast_two_sum(q1, q2);
  bool plain = !dd_finite(q1) || q1 == 0.0lf;
  return plain ? dvec2(q1, 0.0lf) : q;
}
