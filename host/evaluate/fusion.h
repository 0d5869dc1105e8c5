// Decision-level fusion of per-sensor scores at matched false-alarm rates.
//
// Each sensor's alarm threshold is set at one common per-sensor Pfa p: the sensor alarms
// on a row when at most a share p of the negatives score at least that row's score (u, the
// row's per-sensor Pfa, below). OR alarms when any sensor does (min u <= p), AND when all
// do (max u <= p), majority when more than half do (the (n/2 + 1)-th smallest u <= p; with
// two sensors that is AND). Sweeping p from 0 to 1 traces the fused rule's ROC, so the
// fused score of a row is minus that order statistic of its u: the fused ROC, AUC and Pd
// at a target Pfa come from it as from any score, and Pd at Pfa a is the best Pd of a
// common p whose fused Pfa is at most a.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace portalsim::evaluate {

enum class DecisionRule { any, all, majority };  // OR, AND, majority
const char* rule_name(DecisionRule r);           // "or", "and", "majority"

// u of each row: the share of negatives whose score is at least the row's.
std::vector<double> negative_exceedance(const std::vector<double>& score, const std::vector<uint8_t>& label);

// The fused score of each row under `rule`, from the sensors' scores (all the same length).
std::vector<double> decision_fusion(const std::vector<std::vector<double>>& scores, const std::vector<uint8_t>& label,
                                    DecisionRule rule);

}  // namespace portalsim::evaluate
