// The two tests `portalsim validate` puts beside its P values: the thesis's two-sample
// t-test over fold accuracies (table 6.8, Excel's TTEST with two tails, equal variances) and
// the corrected resampled t-test of Nadeau & Bengio (2003) that WEKA's Experimenter uses.
#pragma once
#include <vector>

namespace portalsim::cli {

struct TTest {
  double t = 0, df = 0, p = 1;  // p: two-tailed
};

// Student's two-sample t-test with pooled variance. Needs at least two values in each sample.
TTest student_two_sample(const std::vector<double>& a, const std::vector<double>& b);

// Corrected resampled t-test on paired differences d_j (j over runs x folds):
// t = mean(d) / sqrt((1/n + test_train_ratio) * var(d)), df = n - 1; for k-fold
// cross-validation test_train_ratio = n_test / n_train = 1 / (k - 1).
TTest corrected_resampled(const std::vector<double>& differences, double test_train_ratio);

// A 95% interval of a proportion or of a difference of two, as fractions.
struct Interval {
  double lo = 0, hi = 0;
};
// Wilson's score interval of `correct` of `n` (Newcombe 1998, "Two-sided confidence
// intervals for the single proportion", method 3). Needs n > 0.
Interval wilson(long correct, long n);
// The difference a/na - b/nb of two independent proportions: Newcombe's hybrid score
// interval (Newcombe 1998, "Interval estimation for the difference between independent
// proportions", method 10), from each one's Wilson interval.
Interval newcombe_difference(long a, long na, long b, long nb);

}  // namespace portalsim::cli
