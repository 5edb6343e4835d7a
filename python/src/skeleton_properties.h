// The skeleton's properties, the same on keyanim.Motion and keyanim.Clip. Nodes are the joints
// and End Sites, in file order (parents first); arrays over nodes use this order.
#pragma once
#include "keyanim/offline/report.h"  // node_name: a node's display name, as the reports give it

namespace keyanim::python {

template <class Class, class Get>
void def_skeleton_properties(Class& cls, Get skeleton_of) {
  using Self = typename Class::type;
  cls.def_property_readonly(
      "joint_names",
      [skeleton_of](const Self& self) {
        const Skeleton& s = skeleton_of(self);
        py::list names;
        for (uint32_t i = 0; i < s.joints.size(); ++i) names.append(text(offline::node_name(s, i)));
        return names;
      },
      "Name of every node (joints and End Sites, in file order; an unnamed End Site is\n"
      "'End Site of PARENT'), as `keyanim` reports them. Arrays over nodes use this order.");
  cls.def_property_readonly(
      "is_end_site",
      [skeleton_of](const Self& self) {
        const Skeleton& s = skeleton_of(self);
        py::array_t<bool> out(py::ssize_t(s.joints.size()));
        for (size_t i = 0; i < s.joints.size(); ++i) out.mutable_at(i) = s.joints[i].end_site;
        return out;
      },
      "Boolean array over nodes: True for an End Site (a node without channels that ends a chain).");
  cls.def_property_readonly(
      "parents",
      [skeleton_of](const Self& self) {
        const Skeleton& s = skeleton_of(self);
        py::array_t<int32_t> out(py::ssize_t(s.joints.size()));
        for (size_t i = 0; i < s.joints.size(); ++i) out.mutable_at(i) = s.joints[i].parent;
        return out;
      },
      "int32 array over nodes: the parent's index, -1 for a root. A parent comes before its children.");
  cls.def_property_readonly(
      "offsets",
      [skeleton_of](const Self& self) {
        const Skeleton& s = skeleton_of(self);
        py::array_t<double> out({py::ssize_t(s.joints.size()), py::ssize_t(3)});
        for (size_t i = 0; i < s.joints.size(); ++i)
          for (size_t k = 0; k < 3; ++k) out.mutable_at(i, k) = s.joints[i].offset[k];
        return out;
      },
      "float64 array (nodes, 3): each node's OFFSET from its parent, in the file's length units.");
  cls.def_property_readonly(
      "channel_names",
      [skeleton_of](const Self& self) {
        const Skeleton& s = skeleton_of(self);
        py::list names;
        for (uint32_t i = 0; i < s.joints.size(); ++i)
          for (ChannelType t : s.joints[i].channels) names.append(text(offline::node_name(s, i) + ":" + channel_name(t)));
        return names;
      },
      "Name of every channel, 'JOINT:Xrotation' (as `keyanim plot --channel` takes them), in\n"
      "frame column order.");
}

}  // namespace keyanim::python
