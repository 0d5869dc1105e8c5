// Threat rules (thesis 5.1): a scenario is a threat when the rule holds.
//   rule   := term ('|' term)*        any term holds
//   term   := factor ('&' factor)*    all factors hold (thesis 5.1.2: two or more objects)
//   factor := '!' factor | '(' rule ')' | object[:variant]   present anywhere on the body
//           | class:NAME | family:NAME                        any object of that class or family
// Examples: "gun" (5.1.1), "iron-rod&metal-plate" (5.1.2), "gun|iron-rod&metal-plate", "class:threat".
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace portalsim {

// '!' and '(' nest at most this deep; deeper rules are refused (InputError).
constexpr int kMaxRuleDepth = 64;

class ThreatRule {
 public:
  // Throws InputError naming `where` and the offending position.
  ThreatRule(const Catalogue& cat, const std::string& text, const std::string& where = "--rule");
  ThreatRule(const ThreatRule&) = delete;
  ThreatRule(ThreatRule&&) noexcept;
  ThreatRule& operator=(ThreatRule&&) noexcept;
  ~ThreatRule();
  bool operator()(const Scenario& s) const;
  const std::string& text() const { return text_; }

 private:
  struct Node;
  std::string text_;
  std::unique_ptr<Node> root_;
  const Catalogue* cat_ = nullptr;
};

}  // namespace portalsim
