# A Gmsh box for `mindlin-sphere-cycle` ([-2,2]x[-2,2]x[0,2], groups body, bottom, top) refined
# towards the contact: size hc within 0.8 of the origin, growing to hf at 2.5 (a threshold on the
# distance). Gmsh 4.15:  python refined_box.py hc hf order out.msh   (order 1 or 2)
import gmsh, sys
hc, hf, order, out = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
gmsh.initialize(); gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("box")
occ = gmsh.model.occ
occ.addBox(-2, -2, 0, 4, 4, 2)
occ.synchronize()
gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)], name="body")
def faces(pred):
    return [t for _, t in gmsh.model.getEntities(2) if pred(*gmsh.model.getBoundingBox(2, t))]
e = 1e-6
gmsh.model.addPhysicalGroup(2, faces(lambda x0,y0,z0,x1,y1,z1: abs(z1) < e), name="bottom")
gmsh.model.addPhysicalGroup(2, faces(lambda x0,y0,z0,x1,y1,z1: abs(z0 - 2) < e), name="top")
p = occ.addPoint(0, 0, 0); occ.synchronize()
f = gmsh.model.mesh.field
d = f.add("Distance"); f.setNumbers(d, "PointsList", [p])
t = f.add("Threshold"); f.setNumber(t, "InField", d)
f.setNumber(t, "SizeMin", hc); f.setNumber(t, "SizeMax", hf)
f.setNumber(t, "DistMin", 0.8); f.setNumber(t, "DistMax", 2.5)
f.setAsBackgroundMesh(t)
gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.model.mesh.generate(3)
if order == 2:
    gmsh.model.mesh.setOrder(2)
gmsh.write(out)
nodes = gmsh.model.mesh.getNodes()[0]
print(out, len(nodes), "nodes")
gmsh.finalize()
