"""The paper's running example (Kinegami, Origami 8, section 5): Example 1A, 1B and 1C.

The listing below is the paper's, line for line, after ``from kinegami import *``. Each
``chain.show(...)`` draws a figure; this script saves them (and the pattern) under
``examples/output/`` (or the folder given as its one argument), prints the sizes of the crease
pattern (without the glue tab) and of the sheet (with it) and where the files went.
Run: ``python examples/example1.py [folder]``.

Lengths are in units of r, and the paper's r = 1 is 1 cm (as in examples/designs/example1.json,
whose sheet ``kinegami build`` prints in mm). The listing's ``pattern.save`` writes the DXF with
save()'s default of 1 unit = 1 mm, a tenth of the size; the line after it, which is not the
paper's, writes the same file again with ``units="cm"``, so the DXF you get is true size (in mm,
``$INSUNITS`` = mm: the sheet is 70.7 mm wide, five sides of 14.1 mm).
"""

import os
import sys
from pathlib import Path

import matplotlib

if not os.environ.get("DISPLAY") and not os.environ.get("MPLBACKEND"):
    matplotlib.use("Agg")  # no screen: draw to files only
import matplotlib.pyplot as plt  # noqa: E402

from kinegami import *  # noqa: E402, F403

if len(sys.argv) > 2:
    sys.exit("usage: python example1.py [output-folder]")
OUTPUT = Path(sys.argv[1] if len(sys.argv) == 2 else Path(__file__).parent / "output").resolve()
OUTPUT.mkdir(parents=True, exist_ok=True)
os.chdir(OUTPUT)  # the listing writes "examplePatterns/example1.dxf" relative to here
written = []


def save_figure(name):
    """Save the figure that the last chain.show() drew."""
    path = OUTPUT / name
    plt.gcf().savefig(path, dpi=120, bbox_inches="tight")
    plt.close(plt.gcf())
    written.append(path)


# ---- Example 1A ------------------------------------------------------------------------
r = 1
numSides = 4
chain = KinematicChain(StartTip(numSides, r, Pose=SE3.Trans(3, 3, 0),
                                 length=1.5))
prismatic = PrismaticJoint(numSides, r, neutralLength=3,
                            numLayers=3, coneAngle=np.pi/4, Pose=SE3.Trans([5, 5, 0]))
prismaticIndex = chain.append(prismatic)
revolute = RevoluteJoint(numSides, r, np.pi, SE3.Ry(np.pi/4))
revoluteIndex = chain.append(revolute)
end = EndTip(numSides, r, Pose=SE3.Ry(np.pi/2), length=1.5)
endIndex = chain.append(end)
chain.show(showGlobalFrame=True) #Figure 5(a)
save_figure("figure5a_example1A.png")

# ---- Example 1B ------------------------------------------------------------------------
chain.translateJointAlongAxisOfMotion(revoluteIndex, -7)
chain.show(showGlobalFrame=True) #Figure 5(b)
save_figure("figure5b_translate_revolute.png")
chain.translateJointAlongAxisOfMotion(endIndex, -10,
                                      applyToPreviousWaypoint=True)
chain.show(showGlobalFrame=True) #Figure 5(c)
save_figure("figure5c_translate_end.png")
chain.rotateJointAboutAxisOfMotion(revoluteIndex, -np.pi/3)
chain.show(showGlobalFrame=True)
save_figure("figure5_rotate_revolute.png")
chain.translateJointAlongAxisOfMotion(prismaticIndex, -2,
                                      propogate=False)
chain.show(showGlobalFrame=True) #Figure 5(d)
save_figure("figure5d_example1B.png")
pattern = chain.creasePattern()
pattern.save(dxfName="examplePatterns/example1.dxf")
pattern.save(dxfName="examplePatterns/example1.dxf", units="cm")  # not the paper's: true size
written.append(OUTPUT / "examplePatterns" / "example1.dxf")

# ---- Example 1C ------------------------------------------------------------------------
minPrismaticState, maxPrismaticState = chain.Joints[prismaticIndex].stateRange()
chain.setJointState(prismaticIndex, maxPrismaticState)
chain.setJointState(revoluteIndex, np.pi/2)
chain.show(showGlobalFrame=True) # Figure 5(f)
save_figure("figure5f_example1C.png")

pattern.show()
save_figure("figure5g_pattern.png")

from kinegami.pattern.sheet import flatten  # noqa: E402

xmin, ymin, xmax, ymax = flatten(pattern).bounds
print(f"Example 1: {len(chain.Joints)} joints, total path length "
      f"{chain.totalPathLength():.4f} cm (r = 1 cm)")
print(f"  crease pattern: {pattern.width:.3f} cm x {pattern.height:.3f} cm, without the glue tab")
print(f"  sheet: {xmax - xmin:.3f} cm x {ymax - ymin:.3f} cm with the glue tab "
      f"(kinegami build prints it as {10 * (xmax - xmin):.1f} mm x {10 * (ymax - ymin):.1f} mm)")
print("  examplePatterns/example1.dxf is true size (1 unit = 1 cm, written in mm); the listing's "
      "own save counts 1 unit as 1 mm, save()'s default, and is written over")
print("wrote:")
for path in written:
    print(f"  {path}")
