// All the WEKA work of one portalsim command in one JVM (Java 17 single-file source program,
// run as `java -cp /usr/share/java/weka.jar Weka.java ARGS`): a JVM's start and its
// compiling of WEKA cost more than J48 on a small table, and a classifier trained once can
// score many test sets. Folds are made exactly
// as weka.classifiers.Evaluation.crossValidateModel makes them (copy, randomize with
// new Random(seed), stratify, trainCV(k, i, random), testCV(k, i)), so the overall accuracy
// equals that of WEKA's command line `-x k -s seed`; the accuracy of every fold is kept.
//
// `portalsim validate`: --real R.arff --sim S.arff --folds K --runs N --seed S
//   --classifiers j48,mlp,svm --curve-steps C. Both tables must share one header (validate
//   writes them so). Prints one JSON object on stdout; progress on stderr.
// `transfer` and `tradeoff`: --jobs FILE, one job a line, fields separated by tabs:
//   CLASSIFIER TRAIN.arff FOLDS SEED [TEST.arff ...]. With no test, FOLDS-fold stratified
//   cross-validation seeded SEED (crossValidate below); else trained once on TRAIN and scored
//   on each TEST. Prints a line per job: "CORRECT MISCLASSIFIED" for the CV or for each test.
// Exit status 2 with a message on bad arguments.
import java.util.ArrayList;
import java.util.HashMap;
import java.util.List;
import java.util.Map;
import java.util.Random;
import weka.classifiers.Classifier;
import weka.classifiers.Evaluation;
import weka.core.Instances;
import weka.core.converters.ConverterUtils.DataSource;

public class Weka {
  static String json(String s) {
    StringBuilder b = new StringBuilder("\"");
    for (char c : s.toCharArray()) {
      if (c == '"' || c == '\\') b.append('\\').append(c);
      else if (c == '\n') b.append("\\n");
      else if (c == '\t') b.append("\\t");
      else if (c < 0x20) b.append(String.format("\\u%04x", (int) c));
      else b.append(c);
    }
    return b.append('"').toString();
  }

  static String json(double[] v) {
    StringBuilder b = new StringBuilder("[");
    for (int i = 0; i < v.length; ++i) b.append(i > 0 ? "," : "").append(v[i]);
    return b.append(']').toString();
  }

  static Classifier make(String name) throws Exception {
    switch (name) {
      case "j48": return new weka.classifiers.trees.J48();
      case "mlp": return new weka.classifiers.functions.MultilayerPerceptron();
      case "svm": return new weka.classifiers.functions.SMO();
      default: throw new IllegalArgumentException("unknown classifier " + name + " (j48, mlp or svm)");
    }
  }

  static Instances load(String path) throws Exception {
    Instances d = DataSource.read(path);
    d.setClassIndex(d.numAttributes() - 1);
    return d;
  }

  // Evaluation.crossValidateModel's folds, scored one by one. Returns the JSON object
  // {"folds":[% correct per fold], "correct":N, "misclassified":N, "percent_correct":P}.
  static String crossValidate(String cls, Instances data, int k, long seed) throws Exception {
    double[] folds = new double[k];
    Evaluation all = crossValidated(cls, data, k, seed, folds);
    return "{\"folds\":" + json(folds) + ",\"correct\":" + (long) all.correct() + ",\"misclassified\":"
        + (long) all.incorrect() + ",\"percent_correct\":" + all.pctCorrect() + "}";
  }

  // The folds' evaluation over all of them; each fold's % correct into `folds` where given.
  static Evaluation crossValidated(String cls, Instances data, int k, long seed, double[] folds) throws Exception {
    Random random = new Random(seed);
    data = new Instances(data);
    data.randomize(random);
    if (data.classAttribute().isNominal()) data.stratify(k);
    Evaluation all = new Evaluation(data);
    for (int i = 0; i < k; ++i) {
      Instances train = data.trainCV(k, i, random);
      all.setPriors(train);
      Classifier c = Classifier.makeCopy(make(cls));
      c.buildClassifier(train);
      Instances test = data.testCV(k, i);
      Evaluation fold = new Evaluation(train);
      fold.evaluateModel(c, test);
      all.evaluateModel(c, test);
      if (folds != null) folds[i] = fold.pctCorrect();
    }
    return all;
  }

  // A classifier trained on `train`, scored on `test` as WEKA's command line `-t -T` scores it.
  static Evaluation scored(Classifier c, Instances train, Instances test) throws Exception {
    Evaluation e = new Evaluation(train);
    e.evaluateModel(c, test);
    return e;
  }

  static String trainTest(String cls, Instances train, Instances test) throws Exception {
    Classifier c = make(cls);
    c.buildClassifier(train);
    Evaluation e = scored(c, train, test);
    return "{\"correct\":" + (long) e.correct() + ",\"misclassified\":" + (long) e.incorrect()
        + ",\"percent_correct\":" + e.pctCorrect() + "}";
  }

  // One --jobs line's answer (see the top of this file).
  static String job(String line) throws Exception {
    String[] f = line.split("\t");
    if (f.length < 4) throw new IllegalArgumentException("a job needs CLASSIFIER TRAIN FOLDS SEED: " + line);
    Instances train = load(f[1]);
    if (f.length == 4) {
      Evaluation e = crossValidated(f[0], train, Integer.parseInt(f[2]), Long.parseLong(f[3]), null);
      return (long) e.correct() + " " + (long) e.incorrect();
    }
    Classifier c = make(f[0]);
    c.buildClassifier(train);
    StringBuilder b = new StringBuilder();
    for (int t = 4; t < f.length; ++t) {
      Instances test = load(f[t]);
      if (!train.equalHeaders(test))
        throw new IllegalArgumentException(f[t] + " and " + f[1] + " have different headers");
      Evaluation e = scored(c, train, test);
      b.append(t > 4 ? " " : "").append((long) e.correct()).append(' ').append((long) e.incorrect());
    }
    return b.toString();
  }

  static void jobs(String path) throws Exception {
    for (String line : java.nio.file.Files.readAllLines(java.nio.file.Paths.get(path))) {
      if (line.isEmpty()) continue;
      System.out.println(job(line));
      System.out.flush();
    }
  }

  // Real data in K stratified folds (seeded as above); each fold's training part gets the
  // first m simulated instances (shuffled once with the seed) added, m = 0, n/C, ..., n.
  // The accuracy at each m is that on all the held-out real instances.
  static String curve(String cls, Instances real, Instances sim, int k, long seed, int steps) throws Exception {
    Instances r = new Instances(real);
    Random random = new Random(seed);
    r.randomize(random);
    r.stratify(k);
    Instances s = new Instances(sim);
    s.randomize(new Random(seed));
    StringBuilder b = new StringBuilder("[");
    for (int step = 0; step <= steps; ++step) {
      int m = (int) ((long) s.numInstances() * step / steps);
      Evaluation e = new Evaluation(r);
      Random foldRandom = new Random(seed);
      for (int i = 0; i < k; ++i) {
        Instances train = r.trainCV(k, i, foldRandom);
        for (int j = 0; j < m; ++j) train.add(s.instance(j));
        Classifier c = make(cls);
        c.buildClassifier(train);
        e.evaluateModel(c, r.testCV(k, i));
      }
      b.append(step > 0 ? "," : "").append("{\"sim_added\":").append(m).append(",\"percent_correct\":")
          .append(e.pctCorrect()).append('}');
    }
    return b.append(']').toString();
  }

  public static void main(String[] args) throws Exception {
    Map<String, String> a = new HashMap<>();
    for (int i = 0; i + 1 < args.length; i += 2) a.put(args[i], args[i + 1]);
    if (a.containsKey("--jobs")) {
      jobs(a.get("--jobs"));
      return;
    }
    for (String need : new String[] {"--real", "--sim", "--folds", "--runs", "--seed", "--classifiers"})
      if (!a.containsKey(need)) {
        System.err.println("Weka: missing " + need);
        System.exit(2);
      }
    int k = Integer.parseInt(a.get("--folds"));
    int runs = Integer.parseInt(a.get("--runs"));
    long seed = Long.parseLong(a.get("--seed"));
    int steps = Integer.parseInt(a.getOrDefault("--curve-steps", "0"));
    String[] classifiers = a.get("--classifiers").split(",");
    for (String c : classifiers) make(c);  // rejects unknown names before any work
    Instances real = load(a.get("--real"));
    Instances sim = load(a.get("--sim"));
    if (!real.equalHeaders(sim)) {
      System.err.println("Weka: the real and simulated tables have different headers");
      System.exit(2);
    }
    Instances combined = new Instances(real);
    for (int i = 0; i < sim.numInstances(); ++i) combined.add(sim.instance(i));

    StringBuilder out = new StringBuilder("{\"classifiers\":{");
    for (int ci = 0; ci < classifiers.length; ++ci) {
      String c = classifiers[ci];
      out.append(ci > 0 ? "," : "").append(json(c)).append(":{");
      List<String> realRuns = new ArrayList<>(), simRuns = new ArrayList<>(), combinedRuns = new ArrayList<>();
      for (int r = 0; r < runs; ++r) {
        System.err.printf("validate: %s run %d/%d%n", c, r + 1, runs);
        realRuns.add(crossValidate(c, real, k, seed + r));
        simRuns.add(crossValidate(c, sim, k, seed + r));
        combinedRuns.add(crossValidate(c, combined, k, seed + r));
      }
      out.append("\"real\":").append(realRuns).append(",\"sim\":").append(simRuns).append(",\"combined\":")
          .append(combinedRuns);
      System.err.printf("validate: %s sim-to-real%n", c);
      out.append(",\"sim_to_real\":").append(trainTest(c, sim, real));
      if (steps > 0) {
        System.err.printf("validate: %s learning curve%n", c);
        out.append(",\"curve\":").append(curve(c, real, sim, k, seed, steps));
      }
      if (c.equals("j48")) {
        out.append(",\"trees\":{");
        String[] names = {"real", "sim", "combined"};
        Instances[] sets = {real, sim, combined};
        for (int i = 0; i < 3; ++i) {
          Classifier t = make(c);
          t.buildClassifier(sets[i]);
          out.append(i > 0 ? "," : "").append(json(names[i])).append(':').append(json(t.toString()));
        }
        out.append('}');
      }
      out.append('}');
    }
    System.out.println(out.append("}}"));
  }
}
