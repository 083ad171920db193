// Decodes LCM traffic exactly the way lcm-spy does (lcm.spy.LCMTypeDatabase
// finds the class by the message's fingerprint, then the class's
// DataInput constructor decodes it), on the classpath tools/lcm-spy uses.
// Run as a single-file program:
//   java -cp "$(tools/lcm-spy --print-classpath)" SpyDecodeCheck.java URL SECONDS CHANNEL...
// Prints "decoded CHANNEL CLASS utime=N" once per channel; exits 0 when every
// listed channel was decoded, 1 otherwise.
import java.io.DataInput;
import java.util.Map;
import java.util.Set;
import java.util.TreeMap;
import java.util.TreeSet;
import lcm.lcm.LCM;
import lcm.lcm.LCMDataInputStream;
import lcm.lcm.LCMSubscriber;
import lcm.spy.LCMTypeDatabase;

public class SpyDecodeCheck implements LCMSubscriber {
  private final LCMTypeDatabase types = new LCMTypeDatabase();
  private final Map<String, String> decoded = new TreeMap<>();
  private final Set<String> failed = new TreeSet<>();

  public synchronized void messageReceived(LCM lcm, String channel, LCMDataInputStream ins) {
    if (decoded.containsKey(channel)) return;
    try {
      long fingerprint = ins.readLong();
      ins.reset();
      Class<?> cls = types.getClassByFingerprint(fingerprint);
      if (cls == null) {
        if (failed.add(channel)) System.out.println("unknown type on " + channel);
        return;
      }
      Object msg = cls.getConstructor(DataInput.class).newInstance(ins);
      long utime = cls.getField("utime").getLong(msg);
      decoded.put(channel, cls.getName());
      System.out.println("decoded " + channel + " " + cls.getName() + " utime=" + utime);
    } catch (Exception e) {
      if (failed.add(channel)) System.out.println("decode failed on " + channel + ": " + e);
    }
  }

  public static void main(String[] args) throws Exception {
    LCM lcm = new LCM(args[0]);
    double seconds = Double.parseDouble(args[1]);
    Set<String> expected = new TreeSet<>();
    for (int i = 2; i < args.length; ++i) expected.add(args[i]);
    SpyDecodeCheck check = new SpyDecodeCheck();
    lcm.subscribeAll(check);
    System.out.println("ready");
    long end = System.currentTimeMillis() + (long) (seconds * 1000);
    while (System.currentTimeMillis() < end) {
      synchronized (check) {
        if (check.decoded.keySet().containsAll(expected)) break;
      }
      Thread.sleep(20);
    }
    lcm.close();
    synchronized (check) {
      Set<String> missing = new TreeSet<>(expected);
      missing.removeAll(check.decoded.keySet());
      if (!missing.isEmpty()) System.out.println("not decoded: " + missing);
      System.exit(missing.isEmpty() ? 0 : 1);
    }
  }
}
