// SampleClip: keyanim's C API from C# through P/Invoke, as a Unity plugin calls a native
// library (Plugins/libkeyanim_c.so, or keyanim_c.dll on Windows). The same program as
// examples/c/sample_clip.c, with the same output:
//   mono SampleClip.exe FILE.kanim POSITION...   (a frame position, or t + seconds)
// Build: mcs -out:SampleClip.exe SampleClip.cs   Run with libkeyanim_c.so on LD_LIBRARY_PATH.
using System;
using System.Globalization;
using System.Runtime.InteropServices;
using System.Text;

// keyanim.h's declarations. Handles are IntPtr; keyanim_status is int; size_t is UIntPtr.
static class Keyanim {
  const string Lib = "keyanim_c";

  [StructLayout(LayoutKind.Sequential)]
  public struct Transform {  // keyanim_transform: 32 bytes
    public float RX, RY, RZ, RW;  // rotation quaternion (x, y, z, w)
    public float TX, TY, TZ;      // translation
    public float Pad;
  }

  [DllImport(Lib)] public static extern IntPtr keyanim_status_name(int status);
  [DllImport(Lib)] public static extern int keyanim_last_error_status();
  [DllImport(Lib)] public static extern IntPtr keyanim_last_error_detail();
  [DllImport(Lib)] public static extern int keyanim_clip_load_file(byte[] utf8Path, out IntPtr clip);
  [DllImport(Lib)] public static extern void keyanim_clip_free(IntPtr clip);
  [DllImport(Lib)] public static extern uint keyanim_clip_frame_count(IntPtr clip);
  [DllImport(Lib)] public static extern double keyanim_clip_frame_time(IntPtr clip);
  [DllImport(Lib)] public static extern uint keyanim_clip_channel_count(IntPtr clip);
  [DllImport(Lib)] public static extern uint keyanim_clip_node_count(IntPtr clip);
  [DllImport(Lib)] public static extern IntPtr keyanim_clip_node_name(IntPtr clip, uint node);
  [DllImport(Lib)] public static extern int keyanim_clip_node_parent(IntPtr clip, uint node);
  [DllImport(Lib)] public static extern IntPtr keyanim_clip_skeleton(IntPtr clip);
  [DllImport(Lib)] public static extern int keyanim_skeleton_node_is_end_site(IntPtr skeleton, uint node);
  [DllImport(Lib)] public static extern int keyanim_clip_sample(IntPtr clip, double frame, [Out] float[] o, UIntPtr n);
  [DllImport(Lib)] public static extern int keyanim_clip_sample_local(IntPtr clip, double frame, [Out] Transform[] o, UIntPtr n);
  [DllImport(Lib)] public static extern int keyanim_clip_sample_model(IntPtr clip, double frame, [Out] Transform[] o, UIntPtr n);
  [DllImport(Lib)] public static extern int keyanim_cursor_create(IntPtr clip, out IntPtr cursor);
  [DllImport(Lib)] public static extern void keyanim_cursor_free(IntPtr cursor);
  [DllImport(Lib)] public static extern int keyanim_cursor_sample_time(IntPtr cursor, double seconds, [Out] float[] o, UIntPtr n);
  [DllImport(Lib)] public static extern int keyanim_cursor_sample_local_time(IntPtr cursor, double seconds, [Out] Transform[] o, UIntPtr n);
  [DllImport(Lib)] public static extern int keyanim_cursor_sample_model_time(IntPtr cursor, double seconds, [Out] Transform[] o, UIntPtr n);

  // The library's strings are UTF-8 (node names are the BVH's bytes, here read as Latin-1 so
  // that any byte survives).
  public static string Text(IntPtr p) {
    if (p == IntPtr.Zero) return null;
    int n = 0;
    while (Marshal.ReadByte(p, n) != 0) ++n;
    var bytes = new byte[n];
    Marshal.Copy(p, bytes, 0, n);
    return Encoding.GetEncoding("iso-8859-1").GetString(bytes);
  }
}

static class SampleClip {
  static readonly CultureInfo C = CultureInfo.InvariantCulture;

  static void Check(int status, string what) {
    if (status == 0) return;
    throw new Exception(what + ": " + Keyanim.Text(Keyanim.keyanim_status_name(status)) + ": " +
                        Keyanim.Text(Keyanim.keyanim_last_error_detail()));
  }

  static void Print(string kind, Keyanim.Transform[] pose) {
    for (int i = 0; i < pose.Length; ++i) {
      var t = pose[i];
      Console.WriteLine(string.Format(C, "{0} {1} {2} {3} {4} {5} {6} {7} {8}", kind, i, t.RX.ToString("R", C),
          t.RY.ToString("R", C), t.RZ.ToString("R", C), t.RW.ToString("R", C), t.TX.ToString("R", C),
          t.TY.ToString("R", C), t.TZ.ToString("R", C)));
    }
  }

  static int Main(string[] args) {
    if (args.Length < 1) {
      Console.Error.WriteLine("usage: SampleClip.exe FILE.kanim POSITION...");
      return 2;
    }
    IntPtr clip, cursor;
    var path = Encoding.UTF8.GetBytes(args[0] + "\0");
    Check(Keyanim.keyanim_clip_load_file(path, out clip), args[0]);
    try {
      Check(Keyanim.keyanim_cursor_create(clip, out cursor), "cursor");
      uint nodes = Keyanim.keyanim_clip_node_count(clip), channels = Keyanim.keyanim_clip_channel_count(clip);
      Console.WriteLine(string.Format(C, "clip {0} {1} {2} {3}", Keyanim.keyanim_clip_frame_count(clip),
          Keyanim.keyanim_clip_frame_time(clip).ToString("R", C), nodes, channels));
      IntPtr skeleton = Keyanim.keyanim_clip_skeleton(clip);
      for (uint i = 0; i < nodes; ++i)
        Console.WriteLine(string.Format(C, "node {0} {1} {2} {3}", i, Keyanim.keyanim_clip_node_parent(clip, i),
            Keyanim.keyanim_skeleton_node_is_end_site(skeleton, i), Keyanim.Text(Keyanim.keyanim_clip_node_name(clip, i))));
      // Buffers made once; sampling never allocates. Times go through the cursor here, frames
      // through the clip (examples/c does the opposite): the values are the same.
      var values = new float[channels];
      var pose = new Keyanim.Transform[nodes];
      UIntPtr nv = new UIntPtr(channels), np = new UIntPtr(nodes);
      for (int a = 1; a < args.Length; ++a) {
        string arg = args[a];
        bool byTime = arg.StartsWith("t");
        double x = double.Parse(byTime ? arg.Substring(1) : arg, C);
        Console.WriteLine("at " + (byTime ? "time " : "frame ") + x.ToString("R", C));
        Check(byTime ? Keyanim.keyanim_cursor_sample_time(cursor, x, values, nv) : Keyanim.keyanim_clip_sample(clip, x, values, nv), "sample");
        var line = new StringBuilder("channels");
        foreach (var v in values) line.Append(' ').Append(v.ToString("R", C));
        Console.WriteLine(line.ToString());
        Check(byTime ? Keyanim.keyanim_cursor_sample_local_time(cursor, x, pose, np) : Keyanim.keyanim_clip_sample_local(clip, x, pose, np), "local");
        Print("local", pose);
        Check(byTime ? Keyanim.keyanim_cursor_sample_model_time(cursor, x, pose, np) : Keyanim.keyanim_clip_sample_model(clip, x, pose, np), "model");
        Print("model", pose);
      }
      Keyanim.keyanim_cursor_free(cursor);
    } finally {
      Keyanim.keyanim_clip_free(clip);
    }
    return 0;
  }
}
