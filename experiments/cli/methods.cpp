// `bodypoint methods`: every integration method of the catalogue, as a table, Markdown (README's) or CSV.
#include "bodypoint/batch.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "cli.hpp"

#include <iomanip>
#include <iostream>
#include <string>

namespace bodypoint::cli {

namespace {

/// The README's method table (between its `methods:begin` and `methods:end` markers; ctest
/// ReadmeMethodTableIsGenerated keeps the two equal).
void print_markdown_table() {
  std::cout << "| method | family | order | stages | evals/step | description |\n|---|---|---|---|---|---|\n";
  for (const MethodInfo& m : methods())
    std::cout << "| `" << m.name << "` | " << m.traits.family_name << " | " << (m.order ? std::to_string(m.order) : "var")
              << " | " << stages_text(m) << " | " << evals_per_step_text(m) << " | " << m.description << " |\n";
}

/// One row per method for scripts (paper/ reads the families from it): method, family (family_key),
/// order (0: variable), stages, force evaluations per step, how it advances time, and the family's name.
void print_csv() {
  std::cout << "method,family,order,stages,evals_per_step,advance,family_name,geometry,table,reference\n";
  for (const MethodInfo& m : methods()) {
    CsvLine row;
    row.text(m.name).text(std::string(m.traits.family_key)).count(m.order).count(m.stages).count(m.evals_per_step);
    row.text(std::string(stepping_name(m)));
    row.quoted(std::string(m.traits.family_name)).quoted(geometry_text(m)).text(m.table);
    // The table's citation: what the description names in brackets ("... [Yoshida 1990; thesis eq. 2.9]").
    const std::size_t open = m.description.rfind(" ["), close = m.description.rfind(']');
    row.quoted(open != std::string::npos && close > open ? m.description.substr(open + 2, close - open - 2) : "");
    std::cout << row.str() << "\n";
  }
}

void print_table() {
  std::cout << std::left << std::setw(16) << "method" << std::setw(8) << "order" << std::setw(8)
            << "stages" << std::setw(17) << "evals/step" << "description\n";
  for (const MethodInfo& m : methods())
    std::cout << std::left << std::setw(16) << m.name << std::setw(8)
              << (m.order ? std::to_string(m.order) : "var") << std::setw(8) << stages_text(m) << std::setw(17)
              << evals_per_step_text(m) << m.description << "\n";
}

}  // namespace

int cmd_methods(int argc, char** argv) {
  po::options_description desc("bodypoint methods");
  bool markdown = false, csv = false;
  desc.add_options()("markdown", po::bool_switch(&markdown), "print the table as Markdown (README's Methods section)")(
      "csv", po::bool_switch(&csv), "print one CSV row per method (method, family, order, stages, evals_per_step, advance, family_name, geometry, "
          "table, reference)");
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm, "usage: bodypoint methods [--markdown | --csv]\nLists every integration method.")) return 0;
  if (markdown && csv) throw Error("give --markdown or --csv, not both");
  if (markdown) {
    print_markdown_table();
    return 0;
  }
  if (csv) {
    print_csv();
    return 0;
  }
  print_table();
  const Scene probe = thesis_scene(SceneParams{});
  std::string batched;
  for (const MethodInfo& m : methods())
    if (batch::accepts(m, probe.bodies.front(), probe.centres)) batched += (batched.empty() ? "" : ", ") + std::string(m.name);
  std::cout << "\nsweeps run " << batched << " in batches of " << batch::width() << " vector lanes (" << batch::isa()
            << "; one Coulomb centre at the origin, B != 0; the same bits as alone)\n";
  return 0;
}

}  // namespace bodypoint::cli
