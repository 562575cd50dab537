// Cycles: Tarjan's strongly connected components (Tarjan 1972); a component
// with more than one node, or a node feeding itself, holds a cycle, and a
// breadth-first search inside the component from its first node back to that
// node names the shortest one. Order: Kahn's algorithm (Kahn 1962) with the
// ready nodes kept sorted by file position.

#include "workflow/definition/workflow_graph.h"

#include <algorithm>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "core/errors.h"

namespace mmm::workflow {
namespace {

// Nodes with a unique, non-empty id (first occurrence kept), and the edges
// between them, by index into `ids`.
struct Graph {
  std::vector<std::string> ids;
  std::vector<std::vector<std::size_t>> successors;  // producer -> consumers (with repeats)
};

Graph build_graph(const WorkflowDefinition& definition) {
  Graph graph;
  std::map<std::string, std::size_t, std::less<>> index;
  std::vector<const NodeInstance*> nodes;
  for (const NodeInstance& node : definition.nodes) {
    if (node.id.empty() || index.contains(node.id)) continue;
    index.emplace(node.id, graph.ids.size());
    graph.ids.push_back(node.id);
    nodes.push_back(&node);
  }
  graph.successors.resize(graph.ids.size());
  for (std::size_t consumer = 0; consumer < nodes.size(); ++consumer) {
    for (const auto& [port, connection] : nodes[consumer]->inputs) {
      const Reference& source = connection.source;
      if (!source.well_formed() || source.is_study()) continue;
      const auto it = index.find(source.node);
      if (it != index.end()) graph.successors[it->second].push_back(consumer);
    }
  }
  return graph;
}

class Tarjan {
 public:
  explicit Tarjan(const Graph& graph)
      : graph_(graph), order_(graph.ids.size()), low_(graph.ids.size()) {}

  std::vector<std::vector<std::size_t>> components() {
    for (std::size_t v = 0; v < graph_.ids.size(); ++v) {
      if (!order_[v]) visit(v);
    }
    return std::move(components_);
  }

 private:
  void visit(std::size_t v) {
    order_[v] = low_[v] = counter_++;
    stack_.push_back(v);
    on_stack_.insert(v);
    for (const std::size_t w : graph_.successors[v]) {
      if (!order_[w]) {
        visit(w);
        low_[v] = std::min(low_[v], low_[w]);
      } else if (on_stack_.contains(w)) {
        low_[v] = std::min(low_[v], *order_[w]);
      }
    }
    if (low_[v] == order_[v]) {
      std::vector<std::size_t> component;
      std::size_t w = 0;
      do {
        w = stack_.back();
        stack_.pop_back();
        on_stack_.erase(w);
        component.push_back(w);
      } while (w != v);
      components_.push_back(std::move(component));
    }
  }

  const Graph& graph_;
  std::size_t counter_ = 0;
  std::vector<std::optional<std::size_t>> order_;
  std::vector<std::size_t> low_;
  std::vector<std::size_t> stack_;
  std::set<std::size_t> on_stack_;
  std::vector<std::vector<std::size_t>> components_;
};

// Shortest path start -> ... -> start inside `members`.
std::vector<std::string> cycle_through(const Graph& graph, std::size_t start,
                                       const std::set<std::size_t>& members) {
  std::map<std::size_t, std::size_t> parent;  // node -> predecessor on the search tree
  std::deque<std::size_t> queue{start};
  std::optional<std::size_t> last;  // the node whose edge closes the cycle
  while (!queue.empty() && !last) {
    const std::size_t v = queue.front();
    queue.pop_front();
    for (const std::size_t w : graph.successors[v]) {
      if (w == start) {
        last = v;
        break;
      }
      if (members.contains(w) && !parent.contains(w)) {
        parent[w] = v;
        queue.push_back(w);
      }
    }
  }
  std::vector<std::string> cycle{graph.ids[start]};
  for (std::size_t v = *last; v != start; v = parent.at(v)) cycle.push_back(graph.ids[v]);
  std::reverse(cycle.begin() + 1, cycle.end());
  cycle.push_back(graph.ids[start]);
  return cycle;
}

std::string dot_id(std::string_view text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// A DOT label: text with "\n" line breaks, quoted.
std::string label(const std::vector<std::string>& lines) {
  std::string out = "\"";
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (i > 0) out += "\\n";
    for (const char c : lines[i]) {
      if (c == '"' || c == '\\') out += '\\';
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

std::vector<std::vector<std::string>> find_cycles(const WorkflowDefinition& definition) {
  const Graph graph = build_graph(definition);
  std::vector<std::vector<std::size_t>> components = Tarjan(graph).components();
  std::vector<std::vector<std::string>> cycles;
  std::vector<std::size_t> starts;
  for (const auto& component : components) {
    const std::size_t start = *std::min_element(component.begin(), component.end());
    const auto& next = graph.successors[start];
    const bool self_loop = std::find(next.begin(), next.end(), start) != next.end();
    if (component.size() < 2 && !self_loop) continue;
    starts.push_back(start);
  }
  std::sort(starts.begin(), starts.end());
  for (const std::size_t start : starts) {
    const auto& component = *std::find_if(components.begin(), components.end(), [&](const auto& c) {
      return std::find(c.begin(), c.end(), start) != c.end();
    });
    cycles.push_back(
        cycle_through(graph, start, std::set<std::size_t>(component.begin(), component.end())));
  }
  return cycles;
}

std::vector<std::string> topological_order(const WorkflowDefinition& definition) {
  const Graph graph = build_graph(definition);
  std::vector<std::size_t> in_degree(graph.ids.size(), 0);
  for (const auto& consumers : graph.successors) {
    for (const std::size_t consumer : consumers) ++in_degree[consumer];
  }
  std::set<std::size_t> ready;
  for (std::size_t v = 0; v < graph.ids.size(); ++v) {
    if (in_degree[v] == 0) ready.insert(v);
  }
  std::vector<std::string> order;
  order.reserve(graph.ids.size());
  while (!ready.empty()) {
    const std::size_t v = *ready.begin();
    ready.erase(ready.begin());
    order.push_back(graph.ids[v]);
    for (const std::size_t w : graph.successors[v]) {
      if (--in_degree[w] == 0) ready.insert(w);
    }
  }
  if (order.size() != graph.ids.size()) {
    const auto cycles = find_cycles(definition);
    std::string text;
    for (const std::string& id : cycles.front()) text += (text.empty() ? "" : " -> ") + id;
    throw InvalidInputError("workflow '" + definition.name + "' has no execution order: cycle " +
                            text);
  }
  return order;
}

std::string workflow_to_dot(const WorkflowDefinition& definition, const NodeRegistry& registry) {
  std::ostringstream out;
  out << "digraph " << dot_id(definition.name.empty() ? "workflow" : definition.name) << " {\n";
  out << "  graph [rankdir=LR, fontname=\"Helvetica\", labelloc=t, label="
      << label({definition.description.empty() ? definition.name
                                               : definition.name + ": " + definition.description})
      << "];\n";
  out << "  node [fontname=\"Helvetica\", fontsize=11];\n";
  out << "  edge [fontname=\"Helvetica\", fontsize=9];\n";

  for (const StudyInput& input : definition.inputs) {
    out << "  " << dot_id("study." + input.name)
        << " [shape=ellipse, label=" << label({input.name, input.type_name}) << "];\n";
  }
  const auto spec_of = [&](const NodeInstance& node) -> const NodeSpec* {
    const NodeType* type = registry.find(node.type);
    return type == nullptr ? nullptr : &type->spec;
  };
  std::set<std::string> drawn;
  for (const NodeInstance& node : definition.nodes) {
    if (node.id.empty() || !drawn.insert(node.id).second) continue;
    const NodeSpec* spec = spec_of(node);
    out << "  " << dot_id(node.id) << " [shape=box, ";
    if (spec == nullptr) {
      out << "style=dashed, label=" << label({node.id, node.type + " (unknown type)"});
    } else if (spec->is_manual()) {
      out << R"(style="filled,bold", fillcolor="#ffd966", label=)"
          << label({node.id, node.type, "(manual)"});
    } else {
      out << "label=" << label({node.id, node.type});
    }
    out << "];\n";
  }
  for (const WorkflowOutput& output : definition.outputs) {
    out << "  " << dot_id("output." + output.name) << " [shape=note, label=" << label({output.name})
        << "];\n";
  }

  // The type an edge carries: the producer's when known, else the consumer's.
  const auto produced_type = [&](const Reference& source) -> std::optional<PortType> {
    if (source.is_study()) {
      const StudyInput* input = definition.find_input(source.port);
      return input == nullptr ? std::nullopt : input->type;
    }
    const NodeInstance* producer = definition.find_node(source.node);
    const NodeSpec* spec = producer == nullptr ? nullptr : spec_of(*producer);
    const PortSpec* port = spec == nullptr ? nullptr : spec->find_output(source.port);
    return port == nullptr ? std::nullopt : std::optional<PortType>(port->type);
  };
  const auto endpoint = [&](const Reference& source) -> std::optional<std::string> {
    if (source.is_study()) {
      if (definition.find_input(source.port) == nullptr) return std::nullopt;
      return "study." + source.port;
    }
    if (definition.find_node(source.node) == nullptr) return std::nullopt;
    return source.node;
  };
  for (const NodeInstance& node : definition.nodes) {
    if (node.id.empty()) continue;
    const NodeSpec* spec = spec_of(node);
    for (const auto& [port, connection] : node.inputs) {
      const auto from = endpoint(connection.source);
      if (!connection.source.well_formed() || !from) continue;
      std::optional<PortType> type = produced_type(connection.source);
      const PortSpec* input = spec == nullptr ? nullptr : spec->find_input(port);
      if (!type && input != nullptr) type = input->type;
      const std::string ports =
          connection.source.is_study() ? port : connection.source.port + " -> " + port;
      std::vector<std::string> lines{ports};
      if (type) lines.emplace_back(port_type_name(*type));
      out << "  " << dot_id(*from) << " -> " << dot_id(node.id) << " [label=" << label(lines)
          << "];\n";
    }
  }
  for (const WorkflowOutput& output : definition.outputs) {
    const auto from = endpoint(output.source);
    if (!output.source.well_formed() || !from) continue;
    std::vector<std::string> lines{output.source.port};
    if (const auto type = produced_type(output.source)) lines.emplace_back(port_type_name(*type));
    out << "  " << dot_id(*from) << " -> " << dot_id("output." + output.name)
        << " [style=dashed, label=" << label(lines) << "];\n";
  }
  out << "}\n";
  return out.str();
}

}  // namespace mmm::workflow
