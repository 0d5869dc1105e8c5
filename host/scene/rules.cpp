#include "scene/rules.h"

#include <cctype>
#include <functional>

#include "base/error.h"

namespace portalsim {

struct ThreatRule::Node {
  enum Kind { any_of, all_of, negate, objects, variant } kind = objects;
  std::vector<char> member;  // objects: by object index, whether it is one the factor names
  int id = 0;                // variant: its id
  std::vector<std::unique_ptr<Node>> kids;

  bool eval(const Catalogue* cat, const Scenario& s) const {
    switch (kind) {
      case any_of:
        for (const auto& k : kids)
          if (k->eval(cat, s)) return true;
        return false;
      case all_of:
        for (const auto& k : kids)
          if (!k->eval(cat, s)) return false;
        return true;
      case negate:
        return !kids[0]->eval(cat, s);
      case objects:
        for (int16_t v : s.objects)
          if (v != kNoObject && member[cat->variant_list[v].object]) return true;
        return false;
      case variant:
        for (int16_t v : s.objects)
          if (v == id) return true;
        return false;
    }
    return false;
  }
};

namespace {
struct Parser {
  const Catalogue& cat;
  const std::string& s;
  const std::string& where;
  size_t pos = 0;
  int depth = 0;  // '!' and '(' recurse; a deep nest would overflow the stack

  [[noreturn]] void fail(const std::string& msg) const {
    const std::string shown = s.size() > 80 ? s.substr(0, 60) + "..." : s;  // a long rule is cut, not echoed whole
    throw InputError(where + ": \"" + shown + "\" at character " + std::to_string(pos + 1) + ": " + msg);
  }
  void skip() {
    while (pos < s.size() && std::isspace(static_cast<unsigned char>(s[pos]))) ++pos;
  }
  bool eat(char c) {
    skip();
    if (pos < s.size() && s[pos] == c) {
      ++pos;
      return true;
    }
    return false;
  }
};
}  // namespace

ThreatRule::ThreatRule(ThreatRule&&) noexcept = default;
ThreatRule& ThreatRule::operator=(ThreatRule&&) noexcept = default;
ThreatRule::~ThreatRule() = default;

ThreatRule::ThreatRule(const Catalogue& cat, const std::string& text, const std::string& where) : text_(text) {
  Parser p{cat, text, where};
  std::function<std::unique_ptr<Node>()> rule, term, factor;
  factor = [&]() -> std::unique_ptr<Node> {
    const bool negate = p.eat('!');
    if (negate || p.eat('(')) {
      if (++p.depth > kMaxRuleDepth)
        p.fail("'!' and '(' nested deeper than " + std::to_string(kMaxRuleDepth) + " levels");
      std::unique_ptr<Node> n;
      if (negate) {
        n = std::make_unique<Node>();
        n->kind = Node::negate;
        n->kids.push_back(factor());
      } else {
        n = rule();
        if (!p.eat(')')) p.fail("expected ')'");
      }
      --p.depth;
      return n;
    }
    p.skip();
    const size_t start = p.pos;
    while (p.pos < text.size() && (std::isalnum(static_cast<unsigned char>(text[p.pos])) || text[p.pos] == '-' ||
                                   text[p.pos] == '_' || text[p.pos] == ':'))
      ++p.pos;
    if (p.pos == start) p.fail("expected an object name");
    const std::string token = text.substr(start, p.pos - start);
    if (is_object_set_token(token)) {
      auto n = std::make_unique<Node>();
      n->member.assign(cat.objects.size(), 0);
      for (int o : parse_object_set(cat, token, where, false)) n->member[o] = 1;
      return n;
    }
    const int16_t v = parse_object_token(cat, token, where);
    if (v == kNoObject) p.fail("\"none\" cannot be part of a rule");
    auto n = std::make_unique<Node>();
    if (token.find(':') != std::string::npos) {
      n->kind = Node::variant;
      n->id = v;
    } else {
      n->member.assign(cat.objects.size(), 0);
      n->member[cat.variant_list[v].object] = 1;
    }
    return n;
  };
  // One or more `item`s joined by `op`: a term (factors, '&') or a rule (terms, '|').
  const auto joined = [&](Node::Kind kind, const std::function<std::unique_ptr<Node>()>& item, char op) {
    auto n = std::make_unique<Node>();
    n->kind = kind;
    do n->kids.push_back(item());
    while (p.eat(op));
    return n;
  };
  term = [&] { return joined(Node::all_of, factor, '&'); };
  rule = [&] { return joined(Node::any_of, term, '|'); };
  root_ = rule();
  p.skip();
  if (p.pos != text.size()) p.fail("unexpected character '" + std::string(1, text[p.pos]) + "'");
  cat_ = &cat;
}

bool ThreatRule::operator()(const Scenario& s) const { return root_->eval(cat_, s); }

}  // namespace portalsim
