// The texts built into the binary (CMakeLists.txt's embed_names, written by
// cmake/embed.cmake into the build folder's embedded_resources.cpp): declared once here.
#pragma once

#include <string_view>

namespace portalsim::embedded {

extern const std::string_view kernel_program;     // the kernel program: contract.h, helpers, stages
extern const std::string_view default_catalogue;  // scenarios/catalogue.toml
extern const std::string_view case2_spec;         // scenarios/case2-rod-plate.toml
extern const std::string_view serve_index_html, serve_app_js, serve_style_css;  // host/serve/page/
extern const std::string_view weka_program;                                     // tools/Weka.java
extern const std::string_view transfer_cnn;                                     // tools/transfer_cnn.py
// tools/plot_*.py
extern const std::string_view plot_tradeoff, plot_validate, plot_calibrate, plot_metal_map, plot_evaluate, plot_sweep;

}  // namespace portalsim::embedded
