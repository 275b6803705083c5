// getme.geo -- GETMe adaptive in the ONELAB panel of the plain `gmsh` GUI.
//
// Put   getme_dir = CurrentDirectory;  Include "/path/to/getme.geo";   at the
// end of a model's .geo (after its physical groups) and open it in Gmsh.  The panel then shows a
// "GETMe adaptive" group; ticking "Smooth the mesh" makes Gmsh re-run the
// .geo: it meshes, saves the mesh next to the model, runs the `getme gmsh`
// command on it (a blocking SystemCall) and loads the smoothed mesh in place
// of the model.  Untick to get Gmsh's own mesh back.  See docs/gmsh.md.
DefineConstant[
  getme_run = {0, Choices{0, 1}, Name "GETMe adaptive/0Smooth the mesh"},
  getme_dim = {3, Choices{2="2-D (planar surfaces)", 3="3-D (volumes)"},
               Name "GETMe adaptive/1Mesh dimension"},
  getme_method = {0, Choices{0="getme", 1="laplace"},
                  Name "GETMe adaptive/2Method"},
  getme_sigma = {1.5, Min 0.05, Max 3, Step 0.05,
                 Name "GETMe adaptive/3Sigma"},
  getme_maxiter = {1000, Min 1, Max 100000, Step 1,
                   Name "GETMe adaptive/4Max iterations"},
  getme_fraction = {0.005, Min 0.0001, Max 1, Step 0.001,
                    Name "GETMe adaptive/5Threshold fraction"},
  getme_fix = {"", Name "GETMe adaptive/6Fixed groups (a,b,...)"},
  getme_exe = {"getme", Name "GETMe adaptive/9getme command"}
];
// Files go next to the model: set getme_dir = CurrentDirectory; in the
// model's .geo before the Include (CurrentDirectory here is this file's).
If(!Exists(getme_dir))
  getme_dir = CurrentDirectory;
EndIf
If(getme_run)
  Mesh getme_dim;
  getme_raw = StrCat(getme_dir, "getme_raw.msh");
  getme_out = StrCat(getme_dir, "getme_smoothed.msh");
  Save Str(getme_raw);
  getme_args = Sprintf(" --sigma %g --max-iter %g --threshold-fraction %g",
                       getme_sigma, getme_maxiter, getme_fraction);
  If(getme_method == 1)
    getme_args = StrCat(getme_args, " --method laplace");
  EndIf
  If(StrLen(getme_fix))
    getme_args = StrCat(getme_args, " --fix '", getme_fix, "'");
  EndIf
  SystemCall StrCat(getme_exe, " gmsh '", getme_raw, "' -o '", getme_out,
                    "'", getme_args);
  Delete Model;
  Merge Str(getme_out);
EndIf
