// Runs the thesis code's own solvers (github.com/axothy/Body-point-dynamics) at the settings of its
// harnesses and prints the deviations they printed: java Harness SWEEP VALUE METHOD (paper/java/compare.sh).
import javafx.geometry.Point3D;
import ru.axothy.mechanics.bodypoint.BodyPoint;
import ru.axothy.mechanics.bodypoint.BodyPointMovingData;
import ru.axothy.mechanics.energy.BodyPointEnergy;
import ru.axothy.mechanics.equationsolvers.*;
import ru.axothy.mechanics.motion.BodyPointEquationWithoutTensors;
import ru.axothy.mechanics.tensors.Tensor;
import java.util.Collections;

public class Harness {
    public static void main(String[] a) {
        String sweep = a[0]; double value = Double.parseDouble(a[1]); String method = a[2];
        double m = 1, b = 0.7, j = 1, A = -0.5, h = 0.0001; int n = 250000;
        Point3D v0 = new Point3D(7.058, 0, 6.86), w0 = new Point3D(-2.941, 0, -9.8), r0 = new Point3D(-200, 49, 0);
        if (sweep.equals("d")) r0 = new Point3D(-200, value - 1.0, 0);
        if (sweep.equals("L")) r0 = new Point3D(-value, 49, 0);
        if (sweep.equals("h")) { h = value; n = (int) (25.0 / h); }
        if (sweep.equals("Kx")) {
            double K1 = 5, Kz = 5, Kx = value;
            v0 = new Point3D((b * Kx - j * K1) / (b * b - m * j), 0, -(b * Kz) / (b * b - m * j));
            w0 = new Point3D((b * K1 - m * Kx) / (b * b - m * j), 0, (m * Kz) / (b * b - m * j));
        }
        BodyPoint bp = new BodyPoint(m, Tensor.UNARY_TENSOR, Tensor.UNARY_TENSOR.multiply(b));
        BodyPointEquationWithoutTensors eq = new BodyPointEquationWithoutTensors(bp.getMass(), bp.getJ(), bp.getB(), A);
        BodyPointMovingData data;
        switch (method) {
            case "thesis-euler": data = SymplecticEulerForSystem.solve(eq, r0, v0, w0, h, n); break;
            case "thesis-verlet": data = VerletMethodForSystem.solve(eq, r0, v0, w0, h, n); break;
            case "thesis-ruth3": data = RuthMethodForSystem.solve(eq, r0, v0, w0, h, n); break;
            case "thesis-fr4": data = YoshidaMethodForSystem.solve(eq, r0, v0, w0, h, n); break;
            case "thesis-y6": data = YoshidaMethod6thOrder.solve(eq, r0, v0, w0, h, n); break;
            case "rk4": data = RungeKutta4MethodForSystem.solve(eq, r0, v0, w0, h, n); break;
            case "ab4": data = AdamsBashfortForSystem.solve(eq, r0, v0, w0, h, n); break;
            default: throw new IllegalArgumentException(method);
        }
        BodyPointEnergy e = new BodyPointEnergy();
        e.setMaterialPoint(bp); e.setCoulombConst(A); e.setMovingData(data);
        double dE = Collections.max(e.getRelativeDev());
        double dK2 = Collections.max(e.getRelativeDevK2());
        Point3D rEnd = data.getRadiusVector().get(data.getRadiusVector().size() - 1);
        System.out.println(method + "," + dE + "," + dK2 + "," + rEnd + "," + (data.getRadiusVector().size() - 1));
    }
}
